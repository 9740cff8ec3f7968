#include "learn/intrinsic/saliency.h"

#include <cmath>

#include "core/error.h"

namespace cradle::learn::intrinsic {

double Saliency::of(std::span<const std::uint8_t> rgb, int height, int width,
                    std::vector<double>& gray) {
  const size_t pixels = static_cast<size_t>(height) * width;
  gray.resize(pixels);
  for (size_t p = 0; p < pixels; ++p) {
    gray[p] = 0.2989 * rgb[3 * p] + 0.5870 * rgb[3 * p + 1] + 0.1140 * rgb[3 * p + 2];
  }
  double energy = 0;
  for (int row = 0; row < height; ++row) {
    // Reflect border: a neighbour outside the image is the edge pixel itself.
    const double* here = &gray[static_cast<size_t>(row) * width];
    const double* up = row > 0 ? here - width : here;
    const double* down = row + 1 < height ? here + width : here;
    for (int col = 0; col < width; ++col) {
      const double left = here[col > 0 ? col - 1 : col];
      const double right = here[col + 1 < width ? col + 1 : col];
      const double response = 4 * here[col] - up[col] - down[col] - left - right;
      energy += response * response;
    }
  }
  return std::sqrt(energy) / static_cast<double>(pixels);
}

void Saliency::bind(const VecEnv& env) {
  eyes_.clear();
  const auto& entries = env.observation_space().entries;
  for (int k = 0; k < static_cast<int>(entries.size()); ++k) {
    const Box& box = entries[k].second;
    if (box.dtype == DType::kUInt8 && box.shape.size() == 3 && box.shape[2] == 3) {
      eyes_.push_back({k, box.shape[0], box.shape[1]});
    }
  }
  if (eyes_.empty()) throw UserError("intrinsic reward saliency needs images (vision_active)");
}

void Saliency::compute(const VecEnv& env, std::span<const double>, std::span<double> rewards) {
  if (eyes_.empty()) bind(env);
  for (int i = 0; i < env.num_envs(); ++i) {
    double sum = 0;
    for (const Eye& eye : eyes_) {
      sum += of(env.observation(i).u8(eye.key), eye.height, eye.width, gray_);
    }
    rewards[i] += scale() * sum;
  }
}

}  // namespace cradle::learn::intrinsic

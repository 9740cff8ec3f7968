#include "learn/intrinsic/hand_visibility.h"

#include <cmath>

#include "core/error.h"

namespace cradle::learn::intrinsic {

bool HandVisibility::skin(std::uint8_t r, std::uint8_t g, std::uint8_t b) const {
  const int sum = r + g + b;
  if (sum < options_.min_brightness || sum == 0) return false;
  const double dr = static_cast<double>(r) / sum - options_.skin_r;
  const double dg = static_cast<double>(g) / sum - options_.skin_g;
  return dr * dr + dg * dg <= options_.tolerance * options_.tolerance;
}

const std::vector<double>& HandVisibility::weights(int height, int width) const {
  if (height == weights_height_ && width == weights_width_) return weights_;
  weights_.assign(static_cast<size_t>(height) * width, 0);
  double total = 0;
  for (int y = 0; y < height; ++y) {
    const double dy = (y + 0.5 - 0.5 * height) / (0.5 * height);
    for (int x = 0; x < width; ++x) {
      const double dx = (x + 0.5 - 0.5 * width) / (0.5 * width);
      const double w = std::exp(-(dx * dx + dy * dy) / (2 * options_.sigma * options_.sigma));
      weights_[static_cast<size_t>(y) * width + x] = w;
      total += w;
    }
  }
  for (double& w : weights_) w /= total;
  weights_height_ = height;
  weights_width_ = width;
  return weights_;
}

double HandVisibility::of(std::span<const std::uint8_t> rgb, int height, int width) const {
  const std::vector<double>& w = weights(height, width);
  double sum = 0;
  for (size_t p = 0; p < w.size(); ++p) {
    if (skin(rgb[3 * p], rgb[3 * p + 1], rgb[3 * p + 2])) sum += w[p];
  }
  return sum;
}

void HandVisibility::bind(const VecEnv& env) {
  eyes_.clear();
  const auto& entries = env.observation_space().entries;
  for (int k = 0; k < static_cast<int>(entries.size()); ++k) {
    const Box& box = entries[k].second;
    if (box.dtype == DType::kUInt8 && box.shape.size() == 3 && box.shape[2] == 3) {
      eyes_.push_back({k, box.shape[0], box.shape[1]});
    }
  }
  if (eyes_.empty()) {
    throw UserError("intrinsic reward hand_visibility needs images (vision_active)");
  }
}

void HandVisibility::compute(const VecEnv& env, std::span<const double>,
                             std::span<double> rewards) {
  if (eyes_.empty()) bind(env);
  for (int i = 0; i < env.num_envs(); ++i) {
    double sum = 0;
    for (const Eye& eye : eyes_) sum += of(env.observation(i).u8(eye.key), eye.height, eye.width);
    rewards[i] += scale() * sum / static_cast<double>(eyes_.size());
  }
}

}  // namespace cradle::learn::intrinsic

#include "learn/intrinsic/features.h"

#include <algorithm>
#include <cmath>

namespace cradle::learn::intrinsic {

Features::Features(const VecEnv& env, Options options) : options_(options) {
  const auto& entries = env.observation_space().entries;
  for (int k = 0; k < static_cast<int>(entries.size()); ++k) {
    const auto& [key, box] = entries[k];
    if (key == "touch") {
      if (!options_.touch) continue;
      parts_.push_back({Kind::kTouch, k, box.dtype});
      // The skin's body of each sensor, when the env publishes it.
      const envs::ObservationLayout* skin = env.num_envs() > 0 ? env.env(0).layout(key) : nullptr;
      const std::vector<int>* body = nullptr;
      if (skin) {
        const auto it = skin->groups.find("body");
        if (it != skin->groups.end()) body = &it->second;
      }
      if (body) {
        // One group per run of sensors on the same body (a body's sensors are contiguous).
        const int per = skin->values_per_item;
        for (int s = 0; s < static_cast<int>(body->size()); ++s) {
          if (s == 0 || (*body)[s] != (*body)[s - 1]) touch_ranges_.push_back({s * per, s * per});
          touch_ranges_.back().second = (s + 1) * per;
        }
      } else {
        const int total = box.size();
        const int chunks = std::max(1, std::min(options_.touch_chunks, total));
        for (int c = 0; c < chunks; ++c) {
          touch_ranges_.push_back({total * c / chunks, total * (c + 1) / chunks});
        }
      }
      size_ += static_cast<int>(touch_ranges_.size());
    } else if (box.dtype == DType::kUInt8 && box.shape.size() == 3 && box.shape[2] == 3) {
      if (!options_.images) continue;
      parts_.push_back({Kind::kImage, k, box.dtype, box.shape[0], box.shape[1]});
      size_ += options_.image_cells * options_.image_cells;
    } else if (box.dtype != DType::kUInt8) {
      if (!options_.proprio) continue;
      parts_.push_back({Kind::kCopy, k, box.dtype});
      size_ += box.size();
    }
  }
}

void Features::extract(const VecEnv& env, int i, std::span<float> out) const {
  const envs::ObservationBuffers& obs = env.observation(i);
  float* o = out.data();
  for (const Part& part : parts_) {
    switch (part.kind) {
      case Kind::kCopy:
        if (part.dtype == DType::kFloat64) {
          for (double v : obs.f64(part.key)) *o++ = static_cast<float>(v);
        } else {
          for (float v : obs.f32(part.key)) *o++ = v;
        }
        break;
      case Kind::kTouch: {
        const std::span<const float> touch = obs.f32(part.key);
        for (auto [begin, end] : touch_ranges_) {
          float sum = 0;
          for (int e = begin; e < end; ++e) sum += std::abs(touch[e]);
          *o++ = std::log1p(sum);
        }
        break;
      }
      case Kind::kImage: {
        const std::span<const std::uint8_t> rgb = obs.u8(part.key);
        const int cells = options_.image_cells;
        for (int cy = 0; cy < cells; ++cy) {
          const int y0 = part.height * cy / cells, y1 = part.height * (cy + 1) / cells;
          for (int cx = 0; cx < cells; ++cx) {
            const int x0 = part.width * cx / cells, x1 = part.width * (cx + 1) / cells;
            long sum = 0;
            for (int y = y0; y < y1; ++y) {
              const std::uint8_t* p = &rgb[(static_cast<size_t>(y) * part.width + x0) * 3];
              for (int x = x0; x < x1; ++x, p += 3) sum += p[0] + p[1] + p[2];
            }
            const long n = std::max(1L, 3L * (y1 - y0) * (x1 - x0));
            *o++ = static_cast<float>(static_cast<double>(sum) / (255.0 * n));
          }
        }
        break;
      }
    }
  }
}

void RunningNorm::update(std::span<const float> rows) {
  const size_t dim = mean_.size();
  if (dim == 0) return;
  const size_t n = rows.size() / dim;
  if (n == 0) return;
  // Batch mean and squared deviations, then merged with the running ones.
  std::vector<double> batch_mean(dim, 0), batch_m2(dim, 0);
  for (size_t r = 0; r < n; ++r) {
    for (size_t k = 0; k < dim; ++k) batch_mean[k] += rows[r * dim + k];
  }
  for (double& m : batch_mean) m /= static_cast<double>(n);
  for (size_t r = 0; r < n; ++r) {
    for (size_t k = 0; k < dim; ++k) {
      const double d = rows[r * dim + k] - batch_mean[k];
      batch_m2[k] += d * d;
    }
  }
  const double total = count_ + static_cast<double>(n);
  for (size_t k = 0; k < dim; ++k) {
    const double delta = batch_mean[k] - mean_[k];
    mean_[k] += delta * static_cast<double>(n) / total;
    m2_[k] += batch_m2[k] + delta * delta * count_ * static_cast<double>(n) / total;
  }
  count_ = total;
}

void RunningNorm::apply(std::span<float> rows) const {
  const size_t dim = mean_.size();
  if (dim == 0) return;
  for (size_t r = 0; r < rows.size() / dim; ++r) {
    for (size_t k = 0; k < dim; ++k) {
      const double var = count_ > 1 ? m2_[k] / count_ : 1.0;
      const double z = (rows[r * dim + k] - mean_[k]) / std::sqrt(var + 1e-8);
      rows[r * dim + k] = static_cast<float>(std::clamp(z, -clip_, clip_));
    }
  }
}

nlohmann::json RunningNorm::to_json() const {
  return {{"mean", mean_}, {"m2", m2_}, {"count", count_}, {"clip", clip_}};
}

void RunningNorm::from_json(const nlohmann::json& j) {
  j.at("mean").get_to(mean_);
  j.at("m2").get_to(m2_);
  j.at("count").get_to(count_);
  j.at("clip").get_to(clip_);
}

void RunningStd::update(double x) {
  count_ += 1;
  const double delta = x - mean_;
  mean_ += delta / count_;
  m2_ += delta * (x - mean_);
}

double RunningStd::std() const { return count_ > 1 ? std::sqrt(m2_ / count_) : 1.0; }

double RunningStd::scale(double x) const { return x / (std() + 1e-8); }

}  // namespace cradle::learn::intrinsic

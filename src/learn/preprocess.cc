#include "learn/preprocess.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>

#include "core/error.h"
#include "learn/grad_sync.h"
#include "learn/vec_env.h"

namespace cradle::learn {
namespace {

// The observation key whose layout touch pooling reads.
constexpr const char* kTouchKey = "touch";

}  // namespace

void ObservationConfig::bind(Hyperparameters& table) {
  table.add("normalize_observations", &normalize_observations,
            "standardise the observation vector with running mean/std (VecNormalize norm_obs)");
  table.add("clip_observations", &clip_observations,
            "clip normalised observations to +-this (VecNormalize clip_obs)");
  table.add("pool_touch", &pool_touch,
            "touch as summed force magnitude per MIMo geom instead of the raw skin");
  table.add("policy_images", &policy_images,
            "feed image observations (eyes) to the networks; false: vector keys only, the images "
            "still reach intrinsic rewards");
}

void ObservationConfig::check_matches(const std::string& checkpoint_config) const {
  ObservationConfig saved = *this;
  Hyperparameters table;
  saved.bind(table);
  std::map<std::string, std::string> values;
  for (const auto& [name, value] : parse_hyperparameter_text(checkpoint_config)) {
    if (table.contains(name)) values[name] = value;
  }
  table.apply(values);
  if (saved.normalize_observations != normalize_observations ||
      saved.clip_observations != clip_observations || saved.pool_touch != pool_touch ||
      saved.policy_images != policy_images) {
    throw UserError("observation settings differ (checkpoint: normalize_observations = " +
                    std::string(saved.normalize_observations ? "true" : "false") +
                    ", clip_observations = " + std::to_string(saved.clip_observations) +
                    ", pool_touch = " + (saved.pool_touch ? "true" : "false") +
                    ", policy_images = " + (saved.policy_images ? "true" : "false") + ")");
  }
}

// ---------------------------------------------------------------------------------------------
// Touch pooling

const envs::ObservationLayout* find_touch(const VecEnv& env) {
  return env.num_envs() > 0 ? env.env(0).layout(kTouchKey) : nullptr;
}

TouchPooling::TouchPooling(const envs::ObservationLayout& skin)
    : values_per_sensor_(skin.values_per_item) {
  const auto it = skin.groups.find("geom");
  if (it == skin.groups.end()) throw UserError("touch pooling needs the skin's \"geom\" grouping");
  const std::vector<int>& sensor_geoms = it->second;
  geoms_.assign(sensor_geoms.begin(), sensor_geoms.end());
  std::sort(geoms_.begin(), geoms_.end());
  geoms_.erase(std::unique(geoms_.begin(), geoms_.end()), geoms_.end());
  sensors_ = static_cast<int>(sensor_geoms.size());
  for (int s = 0; s < sensors_; ++s) {
    const int output = static_cast<int>(
        std::lower_bound(geoms_.begin(), geoms_.end(), sensor_geoms[s]) - geoms_.begin());
    if (runs_.empty() || runs_.back().output != output) runs_.push_back({s, s, output});
    runs_.back().end = s + 1;
  }
}

void TouchPooling::pool(std::span<const float> raw, std::span<float> out) const {
  std::fill(out.begin(), out.end(), 0.0f);
  for (const Run& run : runs_) {
    float sum = 0;
    if (values_per_sensor_ == 1) {
      for (int s = run.begin; s < run.end; ++s) sum += std::fabs(raw[s]);
    } else {
      for (int s = run.begin; s < run.end; ++s) {
        const float* f = raw.data() + 3 * s;
        if (f[0] == 0 && f[1] == 0 && f[2] == 0) continue;  // most of the skin feels nothing
        sum += std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
      }
    }
    out[run.output] += sum;
  }
}

// ---------------------------------------------------------------------------------------------
// Running mean and variance

RunningMeanStd::RunningMeanStd(int size)
    : mean_(size, 0.0),
      var_(size, 1.0),
      merged_mean_(mean_),
      merged_var_(var_),
      batch_mean_(size),
      batch_var_(size) {}

void RunningMeanStd::update(std::span<const float> batch, int rows) {
  const int n = size();
  std::fill(batch_mean_.begin(), batch_mean_.end(), 0.0);
  std::fill(batch_var_.begin(), batch_var_.end(), 0.0);
  for (int r = 0; r < rows; ++r) {
    for (int j = 0; j < n; ++j) batch_mean_[j] += batch[r * n + j];
  }
  for (int j = 0; j < n; ++j) batch_mean_[j] /= rows;
  for (int r = 0; r < rows; ++r) {
    for (int j = 0; j < n; ++j) {
      const double d = batch[r * n + j] - batch_mean_[j];
      batch_var_[j] += d * d;
    }
  }
  // Merge: M2 = var * count + batch_var * rows + delta^2 * count * rows / total.
  const double total = count_ + rows;
  for (int j = 0; j < n; ++j) {
    const double delta = batch_mean_[j] - mean_[j];
    const double m2 = var_[j] * count_ + batch_var_[j] + delta * delta * count_ * rows / total;
    mean_[j] += delta * rows / total;
    var_[j] = m2 / total;
  }
  count_ = total;
}

void RunningMeanStd::normalize(std::span<const float> in, std::span<float> out, double clip) const {
  const size_t n = mean_.size();
  for (size_t row = 0; row + n <= in.size() && n > 0; row += n) {
    for (size_t j = 0; j < n; ++j) {
      const double z = (in[row + j] - mean_[j]) / std::sqrt(var_[j] + kVarianceEpsilon);
      out[row + j] = static_cast<float>(std::clamp(z, -clip, clip));
    }
  }
}

void RunningMeanStd::set(std::vector<double> mean, std::vector<double> var, double count) {
  if (mean.size() != mean_.size() || var.size() != var_.size()) {
    throw UserError("observation statistics of size " + std::to_string(mean.size()) +
                    ", expected " + std::to_string(mean_.size()));
  }
  mean_ = std::move(mean);
  var_ = std::move(var);
  count_ = count;
  merged_mean_ = mean_;
  merged_var_ = var_;
  merged_count_ = count_;
}

void RunningMeanStd::merge(GradSync* sync) {
  if (!distributed(sync)) return;
  // Each rank holds G (the last merge, the same everywhere) plus its own new observations. Sum
  // over the ranks the count, and the first and second moments around G's mean (stable for
  // large counts); G then counts world_size times, so world_size - 1 copies are taken out.
  const int n = size();
  const double copies = sync->world_size() - 1;
  sums_.assign(1 + 2 * static_cast<size_t>(n), 0.0);
  sums_[0] = count_;
  for (int j = 0; j < n; ++j) {
    const double d = mean_[j] - merged_mean_[j];
    sums_[1 + j] = count_ * d;
    sums_[1 + n + j] = count_ * (var_[j] + d * d);
  }
  sync->all_reduce_sum(sums_);
  const double total = sums_[0] - copies * merged_count_;
  for (int j = 0; j < n; ++j) {
    const double shift = sums_[1 + j] / total;
    const double m2 = sums_[1 + n + j] - copies * merged_count_ * merged_var_[j];
    mean_[j] = merged_mean_[j] + shift;
    var_[j] = std::max(0.0, m2 / total - shift * shift);
  }
  count_ = total;
  merged_mean_ = mean_;
  merged_var_ = var_;
  merged_count_ = count_;
}

// ---------------------------------------------------------------------------------------------
// Batches

ObsBatch ObsBatch::zeros(const ObsShape& shape, long rows) {
  ObsBatch batch;
  batch.vector = torch::zeros({rows, shape.vector_size}, torch::kFloat32);
  for (const auto& [h, w, c] : shape.images) {
    batch.images.push_back(torch::zeros({rows, h, w, c}, torch::kUInt8));
  }
  return batch;
}

ObsBatch ObsBatch::select(const torch::Tensor& index) const {
  ObsBatch batch;
  batch.vector = vector.index_select(0, index);
  for (const torch::Tensor& image : images) batch.images.push_back(image.index_select(0, index));
  return batch;
}

ObsBatch ObsBatch::slice(long begin, long end) const {
  ObsBatch batch;
  batch.vector = vector.slice(0, begin, end);
  for (const torch::Tensor& image : images) batch.images.push_back(image.slice(0, begin, end));
  return batch;
}

void ObsBatch::assign(long begin, const ObsBatch& source) {
  const long end = begin + source.rows();
  vector.slice(0, begin, end).copy_(source.vector);
  for (size_t k = 0; k < images.size(); ++k) images[k].slice(0, begin, end).copy_(source.images[k]);
}

// ---------------------------------------------------------------------------------------------
// Pipeline

ObservationPipeline::ObservationPipeline(const DictSpace& space, const ObservationConfig& config,
                                         const envs::ObservationLayout* touch)
    : config_(config) {
  int offset = 0;
  for (int key = 0; key < static_cast<int>(space.entries.size()); ++key) {
    const auto& [name, box] = space.entries[key];
    if (box.dtype == DType::kUInt8 && box.shape.size() == 3) {
      if (!config.policy_images) continue;
      image_keys_.push_back(key);
      image_bytes_.push_back(box.size());
      shape_.images.push_back({box.shape[0], box.shape[1], box.shape[2]});
      continue;
    }
    Segment segment{.key = key, .dtype = box.dtype, .offset = offset, .size = box.size()};
    if (name == kTouchKey && config.pool_touch) {
      if (touch == nullptr) {
        throw UserError("pool_touch needs the skin layout the env publishes for \"touch\"");
      }
      pooling_ = std::make_unique<TouchPooling>(*touch);
      if (pooling_->input_size() != box.size()) {
        throw UserError("touch observation has " + std::to_string(box.size()) +
                        " values, the skin " + std::to_string(pooling_->input_size()));
      }
      segment.pooled = true;
      segment.size = pooling_->size();
    }
    offset += segment.size;
    segments_.push_back(segment);
  }
  shape_.vector_size = offset;
  normalizer_ = RunningMeanStd(offset);
}

void ObservationPipeline::raw_vector(const envs::ObservationBuffers& observation,
                                     std::span<float> out) const {
  for (const Segment& s : segments_) {
    float* dst = out.data() + s.offset;
    if (s.pooled) {
      pooling_->pool(observation.f32(s.key), {dst, static_cast<size_t>(s.size)});
    } else if (s.dtype == DType::kFloat64) {
      const std::span<const double> src = observation.f64(s.key);
      for (int j = 0; j < s.size; ++j) dst[j] = static_cast<float>(src[j]);
    } else if (s.dtype == DType::kFloat32) {
      std::memcpy(dst, observation.f32(s.key).data(), s.size * sizeof(float));
    } else {
      const std::span<const std::uint8_t> src = observation.u8(s.key);
      for (int j = 0; j < s.size; ++j) dst[j] = src[j];
    }
  }
}

void ObservationPipeline::gather(const VecEnv& env, ObsBatch& out) {
  const int rows = env.num_envs();
  const int n = shape_.vector_size;
  raw_.resize(static_cast<size_t>(rows) * n);
  for (int i = 0; i < rows; ++i) {
    const envs::ObservationBuffers& observation = env.observation(i);
    raw_vector(observation, {raw_.data() + static_cast<size_t>(i) * n, static_cast<size_t>(n)});
    for (size_t k = 0; k < image_keys_.size(); ++k) {
      std::memcpy(out.images[k].data_ptr<std::uint8_t>() + static_cast<size_t>(i) * image_bytes_[k],
                  observation.u8(image_keys_[k]).data(), image_bytes_[k]);
    }
  }
}

void ObservationPipeline::process(const VecEnv& env, bool update_stats, ObsBatch& out) {
  gather(env, out);
  finish(env.num_envs(), update_stats, out);
}

void ObservationPipeline::process_raw(const VecEnv& env, bool update_stats, ObsBatch& out) {
  gather(env, out);
  const int rows = env.num_envs();
  std::copy(raw_.begin(), raw_.end(), out.vector.data_ptr<float>());
  if (update_stats && config_.normalize_observations) normalizer_.update(raw_, rows);
}

void ObservationPipeline::normalize(const torch::Tensor& raw, torch::Tensor& out) const {
  normalize(raw, out, normalizer_);
}

void ObservationPipeline::normalize(const torch::Tensor& raw, torch::Tensor& out,
                                    const RunningMeanStd& stats) const {
  if (!config_.normalize_observations) {
    out.copy_(raw);
    return;
  }
  const size_t count = static_cast<size_t>(raw.numel());
  stats.normalize({raw.data_ptr<float>(), count}, {out.data_ptr<float>(), count},
                  config_.clip_observations);
}

void ObservationPipeline::process(const envs::ObservationBuffers& observation, ObsBatch& out) {
  const int n = shape_.vector_size;
  raw_.resize(n);
  raw_vector(observation, raw_);
  for (size_t k = 0; k < image_keys_.size(); ++k) {
    std::memcpy(out.images[k].data_ptr<std::uint8_t>(), observation.u8(image_keys_[k]).data(),
                image_bytes_[k]);
  }
  finish(1, false, out);
}

void ObservationPipeline::finish(int rows, bool update_stats, ObsBatch& out) {
  const size_t count = static_cast<size_t>(rows) * shape_.vector_size;
  const std::span<float> dst{out.vector.data_ptr<float>(), count};
  const std::span<const float> raw{raw_.data(), count};
  if (!config_.normalize_observations) {
    std::copy(raw.begin(), raw.end(), dst.begin());
    return;
  }
  if (update_stats) normalizer_.update(raw, rows);
  normalizer_.normalize(raw, dst, config_.clip_observations);
}

void ObservationPipeline::save(torch::serialize::OutputArchive& archive) const {
  const auto options = torch::TensorOptions().dtype(torch::kFloat64);
  const long n = normalizer_.size();
  archive.write(
      "mean",
      torch::from_blob(const_cast<double*>(normalizer_.mean().data()), {n}, options).clone());
  archive.write(
      "var", torch::from_blob(const_cast<double*>(normalizer_.var().data()), {n}, options).clone());
  archive.write("count", torch::tensor({normalizer_.count()}, options));
}

void ObservationPipeline::load(torch::serialize::InputArchive& archive) {
  torch::Tensor mean, var, count;
  archive.read("mean", mean);
  archive.read("var", var);
  archive.read("count", count);
  mean = mean.to(torch::kFloat64).contiguous();
  var = var.to(torch::kFloat64).contiguous();
  normalizer_.set({mean.data_ptr<double>(), mean.data_ptr<double>() + mean.numel()},
                  {var.data_ptr<double>(), var.data_ptr<double>() + var.numel()},
                  count.item<double>());
}

}  // namespace cradle::learn

#include "learn/replay_buffer.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "core/error.h"

namespace cradle::learn {
namespace {

std::string gigabytes(double bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f GB", bytes / 1e9);
  return text;
}

}  // namespace

double replay_bytes(long capacity, const ObsShape& shape, int action_size) {
  double per_transition = 2.0 * 4.0 * shape.vector_size + 4.0 * action_size + 4.0 + 1.0;
  for (const auto& [h, w, c] : shape.images) per_transition += 2.0 * h * w * c;
  return per_transition * static_cast<double>(capacity);
}

double replay_memory_limit() {
  const double pages = static_cast<double>(sysconf(_SC_PHYS_PAGES));
  const double page_size = static_cast<double>(sysconf(_SC_PAGE_SIZE));
  return 0.5 * pages * page_size;
}

void check_replay_memory(std::string_view algorithm, long capacity, const ObsShape& shape,
                         int action_size, double limit_bytes) {
  const std::string name(algorithm);
  if (capacity < 1) throw UserError(name + ": buffer_size must be at least 1");
  const double bytes = replay_bytes(capacity, shape, action_size);
  if (bytes > limit_bytes) {
    throw UserError(name + ": buffer_size = " + std::to_string(capacity) + " needs " +
                    gigabytes(bytes) + " for the replay buffer, more than the " +
                    gigabytes(limit_bytes) +
                    " allowed (half the machine's memory); lower buffer_size (--hp buffer_size=N)");
  }
}

// ---------------------------------------------------------------------------------------------
// Buffer

ReplayBuffer::ReplayBuffer(long capacity, const ObsShape& shape, int action_size)
    : capacity_(capacity) {
  // Uncommitted storage: the pages are touched (and used) as transitions arrive.
  auto empty_batch = [&] {
    ObsBatch batch;
    batch.vector = torch::empty({capacity, shape.vector_size}, torch::kFloat32);
    for (const auto& [h, w, c] : shape.images) {
      batch.images.push_back(torch::empty({capacity, h, w, c}, torch::kUInt8));
    }
    return batch;
  };
  observations_ = empty_batch();
  next_observations_ = empty_batch();
  actions_ = torch::empty({capacity, action_size}, torch::kFloat32);
  rewards_ = torch::empty({capacity}, torch::kFloat32);
  terminated_ = torch::empty({capacity}, torch::kUInt8);
  for (const auto& [h, w, c] : shape.images) image_bytes_.push_back(static_cast<long>(h) * w * c);
}

void ReplayBuffer::add(const ObsBatch& observation, const torch::Tensor& actions,
                       std::span<const double> rewards, const ObsBatch& next,
                       std::span<const std::uint8_t> terminated,
                       std::span<const std::uint8_t> keep) {
  const torch::Tensor source_actions = actions.contiguous();
  for (size_t i = 0; i < keep.size(); ++i) {
    if (!keep[i]) continue;
    put(observation, source_actions, next, static_cast<long>(i), static_cast<float>(rewards[i]),
        terminated[i] ? 1 : 0);
  }
}

void ReplayBuffer::append(ReplayBuffer& staging) {
  const long first = staging.size_ < staging.capacity_ ? 0 : staging.next_;
  for (long k = 0; k < staging.size_; ++k) {
    const long from = (first + k) % staging.capacity_;
    put(staging.observations_, staging.actions_, staging.next_observations_, from,
        staging.rewards_.data_ptr<float>()[from],
        staging.terminated_.data_ptr<std::uint8_t>()[from]);
  }
  staging.size_ = staging.next_ = 0;
}

void ReplayBuffer::put(const ObsBatch& observation, const torch::Tensor& actions,
                       const ObsBatch& next, long from, float reward, std::uint8_t terminated) {
  const long n = observations_.vector.size(1);
  const long a = actions_.size(1);
  const long row = next_;
  // Copies one row of a [rows, ...] tensor into row `row` of the storage.
  auto copy_row = [&](const torch::Tensor& source, torch::Tensor& to, long bytes) {
    std::memcpy(static_cast<char*>(to.data_ptr()) + row * bytes,
                static_cast<const char*>(source.data_ptr()) + from * bytes, bytes);
  };
  copy_row(observation.vector, observations_.vector, n * 4);
  copy_row(next.vector, next_observations_.vector, n * 4);
  for (size_t k = 0; k < image_bytes_.size(); ++k) {
    copy_row(observation.images[k], observations_.images[k], image_bytes_[k]);
    copy_row(next.images[k], next_observations_.images[k], image_bytes_[k]);
  }
  copy_row(actions, actions_, a * 4);
  rewards_.data_ptr<float>()[row] = reward;
  terminated_.data_ptr<std::uint8_t>()[row] = terminated;
  next_ = (next_ + 1) % capacity_;
  size_ = std::min(size_ + 1, capacity_);
}

ReplayBuffer::Sample ReplayBuffer::gather(const torch::Tensor& index) const {
  return {.observations = observations_.select(index),
          .next_observations = next_observations_.select(index),
          .actions = actions_.index_select(0, index),
          .rewards = rewards_.index_select(0, index),
          .terminated = terminated_.index_select(0, index).to(torch::kFloat32)};
}

ReplayBuffer::Sample ReplayBuffer::sample(int rows, at::Generator& generator) const {
  return gather(torch::randint(0, size_, {rows}, generator, torch::kInt64));
}

// ---------------------------------------------------------------------------------------------
// Collection

void unscale_actions(const torch::Tensor& actions, const Box& bounds, std::span<double> out) {
  const torch::Tensor contiguous = actions.contiguous();
  const float* src = contiguous.data_ptr<float>();
  const size_t size = bounds.low.size();
  for (size_t k = 0; k < out.size(); ++k) {
    const size_t j = k % size;
    const double a = std::clamp(static_cast<double>(src[k]), -1.0, 1.0);
    out[k] = bounds.low[j] + 0.5 * (a + 1.0) * (bounds.high[j] - bounds.low[j]);
  }
}

void check_bounded_actions(std::string_view algorithm, const Box& bounds) {
  for (size_t j = 0; j < bounds.low.size(); ++j) {
    if (!std::isfinite(bounds.low[j]) || !std::isfinite(bounds.high[j])) {
      throw UserError(std::string(algorithm) + ": action " + std::to_string(j) +
                      " is unbounded; this learner needs a Box with finite bounds");
    }
  }
}

TransitionCollector::TransitionCollector(VecEnv& env, ObservationPipeline& pipeline,
                                         RewardHook reward_hook)
    : env_(env), pipeline_(pipeline), stepper_(env, std::move(reward_hook)) {
  const int envs = env.num_envs();
  raw_ = ObsBatch::zeros(pipeline.shape(), envs);
  next_raw_ = ObsBatch::zeros(pipeline.shape(), envs);
  normalized_ = ObsBatch::zeros(pipeline.shape(), envs);
  actions_.resize(static_cast<size_t>(envs) * env.action_space().size());
}

void TransitionCollector::start(std::uint64_t seed) {
  stepper_.start(seed);
  pipeline_.process_raw(env_, /*update_stats=*/true, raw_);
  normalize_current();
}

void TransitionCollector::normalize_current() {
  pipeline_.normalize(raw_.vector, normalized_.vector);
  for (size_t k = 0; k < raw_.images.size(); ++k) normalized_.images[k].copy_(raw_.images[k]);
}

void TransitionCollector::step(const torch::Tensor& actions, ReplayBuffer& buffer) {
  unscale_actions(actions, env_.action_space(), actions_);
  stepper_.step(actions_);
  // The next observations: on a done step the final one, which truncation bootstraps from.
  pipeline_.process_raw(env_, /*update_stats=*/true, next_raw_);
  // Real transitions only: an env autoreset by this step has no (s, a, r, s') to store.
  buffer.add(raw_, actions, stepper_.rewards(), next_raw_, env_.terminated(), stepper_.real());
  std::swap(raw_, next_raw_);
  normalize_current();
}

}  // namespace cradle::learn

#include "learn/meta/trajectory_replay.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "core/error.h"
#include "learn/replay_buffer.h"

namespace cradle::learn::meta {

TrajectoryReplay::TrajectoryReplay(int envs, int capacity, int max_len, int obs_size,
                                   int action_size)
    : envs_(envs),
      capacity_(capacity),
      max_len_(max_len),
      obs_size_(obs_size),
      action_size_(action_size) {
  if (envs < 1 || capacity < 1 || max_len < 1 || obs_size < 1 || action_size < 1) {
    throw UserError("sami replay: envs, buffer_size, horizon and sizes must be positive");
  }
  // The BabyBench replay rule: the buffer may take at most half the machine's memory, checked
  // before anything is allocated (buffer_size=1000000000 is a one-line error, not bad_alloc).
  const double step_bytes = 4.0 * (obs_size + action_size + 1);
  const double bytes = static_cast<double>(envs) * capacity *
                       ((max_len + 1.0) * step_bytes + sizeof(int) + 1 + sizeof(double));
  const double limit = replay_memory_limit();
  if (bytes > limit) {
    char text[240];
    std::snprintf(text, sizeof text,
                  "sami: buffer_size = %d trajectories x %d envs x %d steps need %.1f GB for the "
                  "replay, more than the %.1f GB allowed (half the machine's memory); lower "
                  "buffer_size (--hp buffer_size=N)",
                  capacity, envs, max_len + 1, bytes / 1e9, limit / 1e9);
    throw UserError(text);
  }
  const long slots = static_cast<long>(envs) * capacity;
  const long steps = slots * (max_len + 1);
  observations_.assign(steps * obs_size, 0.0f);
  actions_.assign(steps * action_size, 0.0f);
  rewards_.assign(steps, 0.0f);
  length_.assign(slots, 0);
  terminated_.assign(slots, 0);
  average_return_.assign(slots, 0.0);
  head_.assign(envs, 0);
  filled_.assign(envs, 0);
  open_.assign(envs, 0);
}

void TrajectoryReplay::begin(int env, std::span<const float> observation) {
  if (open_[env]) throw std::logic_error("sami replay: begin() with a trajectory open");
  const long s = slot(env, head_[env]);
  filled_[env] = std::max(filled_[env], head_[env] + 1);
  open_[env] = 1;
  length_[s] = 0;
  // Zero the old actions and rewards: padded steps read as no action and no reward.
  const long base = s * (max_len_ + 1);
  std::fill_n(actions_.begin() + base * action_size_, (max_len_ + 1) * action_size_, 0.0f);
  std::fill_n(rewards_.begin() + base, max_len_ + 1, 0.0f);
  std::copy(observation.begin(), observation.end(), observations_.begin() + base * obs_size_);
}

void TrajectoryReplay::add(int env, std::span<const float> action, double reward,
                           std::span<const float> next_observation) {
  const long s = slot(env, head_[env]);
  const int t = length_[s];
  if (!open_[env] || t >= max_len_) throw std::logic_error("sami replay: trajectory too long");
  const long step = s * (max_len_ + 1) + t;
  std::copy(action.begin(), action.end(), actions_.begin() + step * action_size_);
  rewards_[step] = static_cast<float>(reward);
  std::copy(next_observation.begin(), next_observation.end(),
            observations_.begin() + (step + 1) * obs_size_);
  length_[s] = t + 1;
}

void TrajectoryReplay::finish(int env, bool terminated) {
  const long s = slot(env, head_[env]);
  if (!open_[env] || length_[s] == 0) throw std::logic_error("sami replay: empty trajectory");
  double sum = 0;
  const long base = s * (max_len_ + 1);
  for (int t = 0; t < length_[s]; ++t) sum += rewards_[base + t];
  average_return_[s] = sum / length_[s];
  terminated_[s] = terminated;
  open_[env] = 0;
  head_[env] = (head_[env] + 1) % capacity_;
}

int TrajectoryReplay::stored(int env) const {
  // The open slot, when it is one of the used ones, is out of the pool.
  return filled_[env] - (open_[env] && head_[env] < filled_[env] ? 1 : 0);
}

long TrajectoryReplay::index(int env, int k) const {
  const bool skip = open_[env] && head_[env] < filled_[env] && k >= head_[env];
  return slot(env, skip ? k + 1 : k);
}

std::vector<long> TrajectoryReplay::sample(int env, int count, Rng& rng) const {
  const int n = stored(env);
  if (n == 0) throw std::logic_error("sami replay: sampling an empty ring");
  std::vector<long> out(count);
  for (long& i : out) i = index(env, static_cast<int>(rng.next() % n));
  return out;
}

TrajectoryReplay::Batch TrajectoryReplay::gather(const std::vector<long>& indices) const {
  const long b = static_cast<long>(indices.size());
  const long t = max_len_ + 1;
  Batch batch;
  batch.observations = torch::empty({b, t, obs_size_});
  batch.actions = torch::empty({b, t, action_size_});
  batch.rewards = torch::empty({b, t});
  batch.terminated = torch::zeros({b, t});
  batch.lengths = torch::empty({b}, torch::kInt64);
  float* obs = batch.observations.data_ptr<float>();
  float* act = batch.actions.data_ptr<float>();
  float* rew = batch.rewards.data_ptr<float>();
  float* term = batch.terminated.data_ptr<float>();
  std::int64_t* len = batch.lengths.data_ptr<std::int64_t>();
  // One copy per trajectory of each array (slots are contiguous).
  for (long i = 0; i < b; ++i) {
    const long s = indices[i];
    const long base = s * t;
    std::copy_n(observations_.begin() + base * obs_size_, t * obs_size_, obs + i * t * obs_size_);
    std::copy_n(actions_.begin() + base * action_size_, t * action_size_,
                act + i * t * action_size_);
    std::copy_n(rewards_.begin() + base, t, rew + i * t);
    len[i] = length_[s];
    if (terminated_[s]) term[i * t + length_[s] - 1] = 1.0f;
    batch.returns.push_back(average_return_[s]);
  }
  batch.prev_actions = torch::zeros_like(batch.actions);
  batch.prev_actions.narrow(1, 1, t - 1).copy_(batch.actions.narrow(1, 0, t - 1));
  batch.valid = (torch::arange(t).unsqueeze(0) < batch.lengths.unsqueeze(1)).to(torch::kFloat32);
  return batch;
}

namespace {

template <typename T>
constexpr torch::Dtype dtype_of() {
  if constexpr (std::is_same_v<T, float>) return torch::kFloat32;
  if constexpr (std::is_same_v<T, double>) return torch::kFloat64;
  if constexpr (std::is_same_v<T, int>) return torch::kInt32;
  return torch::kUInt8;
}

// A copy of an array as a 1-D tensor of its own type.
template <typename T>
torch::Tensor to_tensor(const std::vector<T>& values) {
  torch::Tensor out = torch::empty({static_cast<long>(values.size())}, dtype_of<T>());
  std::copy(values.begin(), values.end(), out.data_ptr<T>());
  return out;
}

// Reads `name` for `values`: UserError unless it has the array's type and size.
template <typename T>
torch::Tensor read_array(torch::serialize::InputArchive& archive, const std::string& name,
                         const std::vector<T>& values) {
  torch::Tensor stored;
  archive.read(name, stored);
  if (stored.scalar_type() != dtype_of<T>() || stored.dim() != 1 ||
      stored.numel() != static_cast<long>(values.size())) {
    throw UserError("sami replay: " + name + " holds " + std::to_string(stored.numel()) +
                    " values in the checkpoint, " + std::to_string(values.size()) +
                    " here (the number of envs, buffer_size, horizon and the spaces must match)");
  }
  return stored.contiguous();
}

template <typename T>
void copy_array(const torch::Tensor& stored, std::vector<T>& values) {
  const T* data = stored.data_ptr<T>();
  std::copy(data, data + values.size(), values.begin());
}

}  // namespace

void TrajectoryReplay::write(torch::serialize::OutputArchive& archive,
                             const std::string& key) const {
  torch::serialize::OutputArchive nested(archive.compilation_unit());
  nested.write("observations", to_tensor(observations_));
  nested.write("actions", to_tensor(actions_));
  nested.write("rewards", to_tensor(rewards_));
  nested.write("length", to_tensor(length_));
  nested.write("terminated", to_tensor(terminated_));
  nested.write("average_return", to_tensor(average_return_));
  nested.write("head", to_tensor(head_));
  nested.write("filled", to_tensor(filled_));
  nested.write("open", to_tensor(open_));
  archive.write(key, nested);
}

std::function<void()> TrajectoryReplay::stage(torch::serialize::InputArchive& archive,
                                              const std::string& key) {
  torch::serialize::InputArchive nested;
  archive.read(key, nested);
  const torch::Tensor observations = read_array(nested, "observations", observations_);
  const torch::Tensor actions = read_array(nested, "actions", actions_);
  const torch::Tensor rewards = read_array(nested, "rewards", rewards_);
  const torch::Tensor length = read_array(nested, "length", length_);
  const torch::Tensor terminated = read_array(nested, "terminated", terminated_);
  const torch::Tensor average_return = read_array(nested, "average_return", average_return_);
  const torch::Tensor head = read_array(nested, "head", head_);
  const torch::Tensor filled = read_array(nested, "filled", filled_);
  const torch::Tensor open = read_array(nested, "open", open_);
  return [=, this] {
    copy_array(observations, observations_);
    copy_array(actions, actions_);
    copy_array(rewards, rewards_);
    copy_array(length, length_);
    copy_array(terminated, terminated_);
    copy_array(average_return, average_return_);
    copy_array(head, head_);
    copy_array(filled, filled_);
    copy_array(open, open_);
  };
}

torch::Tensor TrajectoryReplay::Batch::encoder_input() const {
  return torch::cat({prev_actions, observations}, 2).transpose(0, 1).contiguous();
}

}  // namespace cradle::learn::meta

#include "learn/vector_env.h"

#include <algorithm>
#include <cstdio>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>

#include "core/error.h"
#include "core/rng.h"
#include "envs/action_check.h"

namespace cradle::learn {
namespace {

// Pool participants for n envs: as asked, at most one per env.
int participants(int threads, size_t envs) {
  if (threads <= 0) threads = static_cast<int>(std::thread::hardware_concurrency());
  return std::clamp(threads, 1, std::max(1, static_cast<int>(envs)));
}

// Checks that envs are present and share one set of spaces.
void check_envs(const std::vector<std::unique_ptr<envs::Env>>& envs) {
  if (envs.empty()) throw std::invalid_argument("ThreadedVecEnv: no envs");
  for (size_t i = 0; i < envs.size(); ++i) {
    if (!envs[i]) throw std::invalid_argument("ThreadedVecEnv: env " + std::to_string(i) + " null");
    if (envs[i]->observation_space() != envs[0]->observation_space() ||
        envs[i]->action_space() != envs[0]->action_space()) {
      throw std::invalid_argument("ThreadedVecEnv: env " + std::to_string(i) +
                                  " has spaces different from env 0's");
    }
  }
}

}  // namespace

ThreadedVecEnv::ThreadedVecEnv(std::vector<std::unique_ptr<envs::Env>> envs, int threads)
    : pool_(participants(threads, envs.size())) {
  envs_ = std::move(envs);
  start();
}

ThreadedVecEnv::ThreadedVecEnv(int num_envs, const EnvFactory& make, int threads)
    : pool_(participants(threads, std::max(num_envs, 0))) {
  // One at a time (factories and GL context creation need not be thread-safe), each env on the
  // thread that will step it.
  envs_.resize(std::max(num_envs, 0));
  std::mutex one_at_a_time;
  pool_.parallel_for(num_envs, [&](int i) {
    std::lock_guard lock(one_at_a_time);
    envs_[i] = make(i);
  });
  start();
}

void ThreadedVecEnv::start() {
  check_envs(envs_);
  const size_t n = envs_.size();
  action_size_ = envs_[0]->action_space().size();
  seeds_.resize(n);
  rewards_.resize(n);
  terminated_.resize(n);
  truncated_.resize(n);
  ended_.resize(n);
}

std::uint64_t ThreadedVecEnv::env_seed(std::uint64_t seed, int env) {
  Rng rng(seed);
  std::uint64_t derived = rng.derive();
  for (int i = 0; i < env; ++i) derived = rng.derive();
  return derived;
}

void ThreadedVecEnv::reset(std::uint64_t seed) {
  // Seeds in order from one generator (env_seed(seed, i) for every i).
  Rng rng(seed);
  for (std::uint64_t& s : seeds_) s = rng.derive();
  pool_.parallel_for(num_envs(), [this](int i) { envs_[i]->reset(seeds_[i]); });
  std::fill(rewards_.begin(), rewards_.end(), 0.0);
  std::fill(terminated_.begin(), terminated_.end(), 0);
  std::fill(truncated_.begin(), truncated_.end(), 0);
  std::fill(ended_.begin(), ended_.end(), 0);
  if (after_step_) after_step_();
  if (after_reset_) after_reset_();
}

void ThreadedVecEnv::step(std::span<const double> actions) {
  if (actions.size() != envs_.size() * action_size_) {
    throw std::invalid_argument("ThreadedVecEnv::step: expected " +
                                std::to_string(envs_.size() * action_size_) +
                                " action values, got " + std::to_string(actions.size()));
  }
  envs::check_finite_actions(actions, action_size_);
  pool_.parallel_for(num_envs(), [this, actions](int i) {
    // Next-step autoreset: an env that ended last call starts its next episode instead.
    if (ended_[i]) {
      envs_[i]->reset();
      rewards_[i] = 0;
      terminated_[i] = truncated_[i] = ended_[i] = 0;
      return;
    }
    const envs::StepResult r = envs_[i]->step(actions.subspan(i * action_size_, action_size_));
    rewards_[i] = r.reward;
    terminated_[i] = r.terminated;
    truncated_[i] = r.truncated;
    ended_[i] = r.terminated || r.truncated;
  });
  if (after_step_) after_step_();
}

void ThreadedVecEnv::reset_ended() {
  pool_.parallel_for(num_envs(), [this](int i) {
    if (!ended_[i]) return;
    envs_[i]->reset();
    ended_[i] = 0;
  });
  if (after_step_) after_step_();
}

int ThreadedVecEnv::key_size(int key_index) const {
  return observation_space().entries.at(key_index).second.size();
}

void ThreadedVecEnv::gather(int key_index, std::span<float> out) const {
  const size_t size = key_size(key_index);
  if (out.size() != envs_.size() * size) {
    throw std::invalid_argument("ThreadedVecEnv::gather: output size mismatch");
  }
  const DType dtype = observation_space().entries[key_index].second.dtype;
  for (size_t i = 0; i < envs_.size(); ++i) {
    const envs::ObservationBuffers& obs = envs_[i]->observation();
    float* dst = out.data() + i * size;
    switch (dtype) {
      case DType::kFloat32:
        std::ranges::copy(obs.f32(key_index), dst);
        break;
      case DType::kFloat64:
        std::ranges::transform(obs.f64(key_index), dst,
                               [](double v) { return static_cast<float>(v); });
        break;
      case DType::kUInt8:
        std::ranges::transform(obs.u8(key_index), dst,
                               [](std::uint8_t v) { return static_cast<float>(v); });
        break;
    }
  }
}

void ThreadedVecEnv::gather(int key_index, std::span<std::uint8_t> out) const {
  const size_t size = key_size(key_index);
  if (observation_space().entries[key_index].second.dtype != DType::kUInt8) {
    throw std::invalid_argument("ThreadedVecEnv::gather: key is not uint8");
  }
  if (out.size() != envs_.size() * size) {
    throw std::invalid_argument("ThreadedVecEnv::gather: output size mismatch");
  }
  for (size_t i = 0; i < envs_.size(); ++i) {
    std::ranges::copy(envs_[i]->observation().u8(key_index), out.data() + i * size);
  }
}

}  // namespace cradle::learn

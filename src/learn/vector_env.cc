#include "learn/vector_env.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <mutex>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>
#include <utility>

#include "core/error.h"
#include "core/rng.h"
#include "core/spin.h"
#include "envs/action_check.h"
#include "learn/proc_vector_env.h"

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

// How long an idle async worker polls before sleeping: a job sent soon after then needs no futex
// round trip. The caller never polls in recv(): the other envs keep the workers busy while it
// sleeps, and on 2 cores its polling would take a worker's core.
constexpr std::chrono::microseconds kAsyncSpin{50};

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

// ---------------------------------------------------------------------------------------------
// AsyncVecEnv

AsyncVecEnv::AsyncVecEnv(std::vector<std::unique_ptr<envs::Env>> envs, int batch_size, int threads)
    : envs_(std::move(envs)), batch_size_(batch_size) {
  check_envs(envs_);
  const int n = num_envs();
  if (batch_size < 1 || batch_size > n) {
    throw UserError("async vector env: batch_size " + std::to_string(batch_size) +
                    " must be between 1 and the number of envs (" + std::to_string(n) + ")");
  }
  action_size_ = envs_[0]->action_space().size();
  actions_.resize(static_cast<size_t>(n) * action_size_);
  jobs_.assign(n, Job::kStep);
  seeds_.resize(n);
  rewards_.resize(n);
  terminated_.resize(n);
  truncated_.resize(n);
  ended_.resize(n);
  errors_.resize(n);
  held_.assign(n, 1);
  marked_.assign(n, 0);
  held_count_ = n;
  ids_.reserve(n);
  all_ids_.resize(n);
  for (int e = 0; e < n; ++e) all_ids_[e] = e;
  batch_rewards_.resize(n);
  batch_terminated_.resize(n);
  batch_truncated_.resize(n);
  queue_.resize(n);
  ready_.resize(n);
  const int count = participants(threads, envs_.size());
  workers_.reserve(count);
  try {
    for (int w = 0; w < count; ++w) workers_.emplace_back([this] { worker_loop(); });
  } catch (const std::system_error& error) {
    stop_workers();
    throw UserError("cannot start " + std::to_string(count) + " threads (" + error.what() +
                    "); use fewer envs or --threads");
  }
}

AsyncVecEnv::~AsyncVecEnv() { stop_workers(); }

void AsyncVecEnv::stop_workers() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
  }
  work_cv_.notify_all();
  for (std::thread& worker : workers_) worker.join();
  workers_.clear();
}

void AsyncVecEnv::worker_loop() {
  const int n = num_envs();
  for (;;) {
    // Take the oldest queued job, polling briefly before sleeping.
    spin_until([this] { return queued_.load(std::memory_order_acquire) > 0; }, kAsyncSpin);
    int e = 0;
    {
      std::unique_lock lock(mutex_);
      while (!stop_ && queued_.load(std::memory_order_relaxed) == 0) {
        ++sleeping_workers_;
        work_cv_.wait(lock);
        --sleeping_workers_;
      }
      if (stop_) return;
      e = queue_[queue_head_];
      queue_head_ = (queue_head_ + 1) % n;
      queued_.fetch_sub(1, std::memory_order_relaxed);
    }
    run(e);
    // Hand it back; wake the caller once its batch is complete.
    bool wake = false;
    {
      std::lock_guard lock(mutex_);
      const int count = finished_.load(std::memory_order_relaxed);
      ready_[(ready_head_ + count) % n] = e;
      finished_.store(count + 1, std::memory_order_release);
      wake = caller_wants_ > 0 && count + 1 >= caller_wants_;
    }
    if (wake) ready_cv_.notify_one();
  }
}

void AsyncVecEnv::run(int e) {
  try {
    if (jobs_[e] == Job::kReset) {
      jobs_[e] = Job::kStep;
      envs_[e]->reset(seeds_[e]);
    } else if (ended_[e]) {
      // Next-step autoreset, as in the lock-step vector.
      envs_[e]->reset();
    } else {
      const std::span<const double> action(actions_.data() + static_cast<size_t>(e) * action_size_,
                                           action_size_);
      const envs::StepResult r = envs_[e]->step(action);
      rewards_[e] = r.reward;
      terminated_[e] = r.terminated;
      truncated_[e] = r.truncated;
      ended_[e] = r.terminated || r.truncated;
      return;
    }
    rewards_[e] = 0;
    terminated_[e] = truncated_[e] = ended_[e] = 0;
  } catch (...) {
    errors_[e] = std::current_exception();
  }
}

void AsyncVecEnv::enqueue(std::span<const int> ids) {
  const int n = num_envs();
  int sleeping = 0;
  {
    std::lock_guard lock(mutex_);
    int count = queued_.load(std::memory_order_relaxed);
    for (int id : ids) queue_[(queue_head_ + count++) % n] = id;
    queued_.store(count, std::memory_order_release);
    sleeping = sleeping_workers_;
  }
  if (sleeping == 1 || ids.size() == 1) {
    if (sleeping > 0) work_cv_.notify_one();
  } else if (sleeping > 1) {
    work_cv_.notify_all();
  }
}

void AsyncVecEnv::take(int want) {
  const int n = num_envs();
  ids_.clear();
  {
    std::unique_lock lock(mutex_);
    while (finished_.load(std::memory_order_relaxed) < want) {
      caller_wants_ = want;
      ready_cv_.wait(lock);
    }
    caller_wants_ = 0;
    for (int j = 0; j < want; ++j) {
      ids_.push_back(ready_[ready_head_]);
      ready_head_ = (ready_head_ + 1) % n;
    }
    finished_.fetch_sub(want, std::memory_order_relaxed);
  }
  for (int id : ids_) held_[id] = 1;
  held_count_ += want;
  // An env's failure surfaces when it comes back.
  for (int id : ids_) {
    if (errors_[id]) std::rethrow_exception(std::exchange(errors_[id], nullptr));
  }
}

void AsyncVecEnv::send(std::span<const double> actions, std::span<const int> ids) {
  const int n = num_envs();
  if (actions.size() != ids.size() * action_size_) {
    throw UserError("AsyncVecEnv::send: " + std::to_string(ids.size()) + " env ids need " +
                    std::to_string(ids.size() * action_size_) + " action values, got " +
                    std::to_string(actions.size()));
  }
  // Every id must name a held env, once.
  std::string wrong;
  size_t checked = 0;
  for (; checked < ids.size() && wrong.empty(); ++checked) {
    const int id = ids[checked];
    if (id < 0 || id >= n) {
      wrong =
          "env id " + std::to_string(id) + " is out of range (0.." + std::to_string(n - 1) + ")";
    } else if (!held_[id]) {
      wrong = "env " + std::to_string(id) + " is in flight or ready, not held (recv it first)";
    } else if (marked_[id]) {
      wrong = "env " + std::to_string(id) + " is named twice";
    } else {
      marked_[id] = 1;
    }
  }
  for (size_t k = 0; k < checked; ++k) {
    if (ids[k] >= 0 && ids[k] < n) marked_[ids[k]] = 0;
  }
  if (!wrong.empty()) throw UserError("AsyncVecEnv::send: " + wrong);
  envs::check_finite_actions(actions, action_size_);

  for (size_t k = 0; k < ids.size(); ++k) {
    std::copy_n(actions.data() + k * action_size_, action_size_,
                actions_.data() + static_cast<size_t>(ids[k]) * action_size_);
    held_[ids[k]] = 0;
  }
  held_count_ -= static_cast<int>(ids.size());
  enqueue(ids);
}

AsyncVecEnv::Batch AsyncVecEnv::recv() {
  const int in_flight = num_envs() - held_count_;
  if (in_flight == 0) {
    throw UserError("AsyncVecEnv::recv: no env is in flight (all " + std::to_string(num_envs()) +
                    " are held); send some first");
  }
  const int size = std::min(batch_size_, in_flight);
  take(size);
  for (int j = 0; j < size; ++j) {
    const int e = ids_[j];
    batch_rewards_[j] = rewards_[e];
    batch_terminated_[j] = terminated_[e];
    batch_truncated_[j] = truncated_[e];
  }
  if (after_step_) after_step_();
  const size_t count = size;
  return {.ids = {ids_.data(), count},
          .rewards = {batch_rewards_.data(), count},
          .terminated = {batch_terminated_.data(), count},
          .truncated = {batch_truncated_.data(), count}};
}

void AsyncVecEnv::reset(std::uint64_t seed) {
  const int n = num_envs();
  // Let the envs in flight finish first (their results are dropped).
  if (held_count_ < n) take(n - held_count_);
  Rng rng(seed);
  for (int e = 0; e < n; ++e) {
    seeds_[e] = rng.derive();
    jobs_[e] = Job::kReset;
    held_[e] = 0;
  }
  held_count_ = 0;
  enqueue(all_ids_);
  take(n);
  if (after_step_) after_step_();
  if (after_reset_) after_reset_();
}

void AsyncVecEnv::step(std::span<const double> actions) {
  const int n = num_envs();
  if (held_count_ != n) {
    throw UserError("AsyncVecEnv::step: lock-step needs every env held, " +
                    std::to_string(n - held_count_) + " of " + std::to_string(n) +
                    " are in flight or ready (recv them first)");
  }
  if (actions.size() != static_cast<size_t>(n) * action_size_) {
    throw UserError("AsyncVecEnv::step: expected " + std::to_string(n * action_size_) +
                    " action values, got " + std::to_string(actions.size()));
  }
  send(actions, all_ids_);
  take(n);
  if (after_step_) after_step_();
}

void set_after_reset(VecEnv& vec, std::function<void()> fn) {
  if (auto* threaded = dynamic_cast<ThreadedVecEnv*>(&vec)) {
    threaded->set_after_reset(std::move(fn));
  } else if (auto* async = dynamic_cast<AsyncVecEnv*>(&vec)) {
    async->set_after_reset(std::move(fn));
  } else if (auto* procs = dynamic_cast<ProcVecEnv*>(&vec)) {
    procs->set_after_reset(std::move(fn));
  } else {
    throw std::invalid_argument("set_after_reset: not a ThreadedVecEnv, AsyncVecEnv or ProcVecEnv");
  }
}

void BatchView::reset(std::uint64_t) {
  throw std::logic_error("BatchView::reset: a batch view cannot reset");
}

void BatchView::step(std::span<const double>) {
  throw std::logic_error("BatchView::step: a batch view cannot step");
}

}  // namespace cradle::learn

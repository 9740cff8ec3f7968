#include "core/thread_pool.h"

#include <algorithm>
#include <chrono>
#include <string>
#include <system_error>

#include "core/error.h"
#include "core/spin.h"

namespace cradle {
namespace {

// How long a participant polls before sleeping (spin_until). A loop that follows soon after the
// last one (an env step after the learner's forward pass) then starts, and a caller whose share
// ended first sees the others finish, without a futex round trip. The polls yield the core after
// a few microseconds, so a longer budget costs no other thread its CPU: 1 ms against 250 us gave
// PPO with its overlapped update 3-5 % more env steps/s; 2,000 pauses (about 40 us, before the
// polls yielded) lost 10 % of 2-env throughput against 250 us (BM_VecEnvScalingSelfTouch).
constexpr std::chrono::microseconds kSpinTime{1000};

}  // namespace

ThreadPool::ThreadPool(int threads) {
  if (threads <= 0) threads = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  workers_.reserve(threads - 1);
  try {
    for (int p = 1; p < threads; ++p) workers_.emplace_back([this, p] { worker_loop(p); });
  } catch (const std::system_error& error) {
    // No destructor runs for a half-built pool: stop and join the workers started so far.
    stop_workers();
    throw UserError("cannot start " + std::to_string(threads) + " threads (" + error.what() +
                    "); use fewer envs or --threads");
  }
}

ThreadPool::~ThreadPool() { stop_workers(); }

void ThreadPool::stop_workers() {
  {
    std::lock_guard lock(mutex_);
    stop_.store(true, std::memory_order_relaxed);
    generation_.fetch_add(1, std::memory_order_release);
  }
  start_cv_.notify_all();
  for (std::thread& worker : workers_) worker.join();
  workers_.clear();
}

void ThreadPool::run(int n, Task task) {
  if (n <= 0) return;
  // Inline: nothing to share, or nobody to share with (exceptions propagate as they are).
  if (workers_.empty() || n == 1) {
    for (int i = 0; i < n; ++i) task.call(task.target, i);
    return;
  }
  // Publish the loop, then wake the workers.
  task_ = task;
  n_ = n;
  error_ = nullptr;
  failed_.store(false, std::memory_order_relaxed);
  pending_.store(static_cast<int>(workers_.size()), std::memory_order_relaxed);
  {
    std::lock_guard lock(mutex_);
    generation_.fetch_add(1, std::memory_order_release);
  }
  start_cv_.notify_all();

  work(0);

  // Wait for the workers: poll, then sleep.
  if (!spin_until([this] { return pending_.load(std::memory_order_acquire) == 0; }, kSpinTime)) {
    std::unique_lock lock(mutex_);
    done_cv_.wait(lock, [this] { return pending_.load(std::memory_order_acquire) == 0; });
  }
  if (failed_.load(std::memory_order_relaxed)) {
    std::exception_ptr error;
    std::swap(error, error_);
    std::rethrow_exception(error);
  }
}

void ThreadPool::work(int participant) {
  const int stride = size();
  try {
    for (int i = participant; i < n_; i += stride) {
      if (failed_.load(std::memory_order_relaxed)) return;
      task_.call(task_.target, i);
    }
  } catch (...) {
    std::lock_guard lock(mutex_);
    if (!error_) error_ = std::current_exception();
    failed_.store(true, std::memory_order_relaxed);
  }
}

void ThreadPool::worker_loop(int participant) {
  std::uint32_t seen = 0;
  for (;;) {
    // Wait for the next loop: poll, then sleep.
    std::uint32_t generation = seen;
    if (!spin_until(
            [&] {
              generation = generation_.load(std::memory_order_acquire);
              return generation != seen;
            },
            kSpinTime)) {
      std::unique_lock lock(mutex_);
      start_cv_.wait(lock, [&] {
        generation = generation_.load(std::memory_order_acquire);
        return generation != seen;
      });
    }
    seen = generation;
    if (stop_.load(std::memory_order_relaxed)) return;

    work(participant);
    // The last worker out wakes the caller (under the mutex, so the wake cannot be lost).
    if (pending_.fetch_sub(1, std::memory_order_acq_rel) == 1) {
      std::lock_guard lock(mutex_);
      done_cv_.notify_one();
    }
  }
}

}  // namespace cradle

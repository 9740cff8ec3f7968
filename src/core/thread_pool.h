// A fixed pool of worker threads running an indexed parallel-for. The calling thread is one of the
// participants. Work is split statically: for a given n, index i always runs on participant
// i % size() (participant 0 is the caller), so repeated loops over the same objects keep each
// object on one thread. A call allocates nothing; one thread at a time may call parallel_for.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <memory>
#include <mutex>
#include <thread>
#include <type_traits>
#include <vector>

namespace cradle {

class ThreadPool {
 public:
  // `threads` participants including the caller (<= 0: hardware concurrency; 1: run inline).
  // UserError when the system cannot start that many threads (those started are joined).
  explicit ThreadPool(int threads);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  int size() const { return static_cast<int>(workers_.size()) + 1; }

  // Runs body(i) for every i in [0, n) and returns when all are done. If bodies throw, the
  // participants stop taking new indices and the first exception is rethrown here.
  template <class Body>
  void parallel_for(int n, Body&& body) {
    using Target = std::remove_reference_t<Body>;
    run(n, {const_cast<void*>(static_cast<const void*>(std::addressof(body))),
            [](void* target, int i) { (*static_cast<Target*>(target))(i); }});
  }

 private:
  // A borrowed reference to a callable (no allocation, unlike std::function).
  struct Task {
    void* target = nullptr;
    void (*call)(void*, int) = nullptr;
  };

  void run(int n, Task task);
  // Runs participant p's share of the current loop, catching the first exception.
  void work(int participant);
  void worker_loop(int participant);
  // Wakes every worker to exit and joins them.
  void stop_workers();

  std::vector<std::thread> workers_;
  // The current loop, published by bumping generation_.
  Task task_;
  int n_ = 0;
  std::atomic<std::uint32_t> generation_{0};
  std::atomic<int> pending_{0};  // workers still running the current loop
  std::atomic<bool> failed_{false};
  std::atomic<bool> stop_{false};
  std::exception_ptr error_;
  std::mutex mutex_;  // guards error_ and the sleeping side of both condition variables
  std::condition_variable start_cv_, done_cv_;
};

}  // namespace cradle

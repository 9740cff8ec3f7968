// The thread pool: every index runs exactly once for any n, static assignment, exceptions reach
// the caller and leave the pool usable.
#include "core/thread_pool.h"

#include <gtest/gtest.h>
#include <pthread.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "core/error.h"

namespace cradle {
namespace {

TEST(ThreadPool, CoversEveryIndexOnce) {
  for (int threads : {1, 2, 3, 4}) {
    ThreadPool pool(threads);
    EXPECT_EQ(pool.size(), threads);
    for (int n : {0, 1, threads - 1, threads, threads + 1, 1000}) {
      std::vector<std::atomic<int>> hits(std::max(n, 1));
      pool.parallel_for(n, [&](int i) { hits[i].fetch_add(1); });
      for (int i = 0; i < n; ++i) EXPECT_EQ(hits[i].load(), 1) << threads << " " << n << " " << i;
    }
  }
}

TEST(ThreadPool, DefaultSizeIsHardwareConcurrency) {
  ThreadPool pool(0);
  EXPECT_EQ(pool.size(), std::max(1, static_cast<int>(std::thread::hardware_concurrency())));
}

TEST(ThreadPool, AssignmentIsStatic) {
  ThreadPool pool(3);
  const int n = 10;
  std::vector<std::thread::id> first(n), again(n);
  pool.parallel_for(n, [&](int i) { first[i] = std::this_thread::get_id(); });
  for (int round = 0; round < 20; ++round) {
    pool.parallel_for(n, [&](int i) { again[i] = std::this_thread::get_id(); });
    EXPECT_EQ(again, first);
  }
  // Index i on participant i % 3; participant 0 is the caller.
  for (int i = 0; i < n; ++i) {
    EXPECT_EQ(first[i], first[i % 3]);
    EXPECT_EQ(first[i] == std::this_thread::get_id(), i % 3 == 0);
  }
  EXPECT_NE(first[1], first[2]);
}

TEST(ThreadPool, ManyShortLoops) {
  ThreadPool pool(2);
  std::atomic<long> sum{0};
  for (int round = 0; round < 5000; ++round) {
    pool.parallel_for(3, [&](int i) { sum.fetch_add(i); });
  }
  EXPECT_EQ(sum.load(), 5000L * 3);
}

TEST(ThreadPool, ExceptionsReachTheCaller) {
  for (int threads : {1, 2, 4}) {
    ThreadPool pool(threads);
    for (int thrower : {0, 1, 3, 99}) {
      EXPECT_THROW(pool.parallel_for(100,
                                     [&](int i) {
                                       if (i == thrower) throw std::runtime_error("boom");
                                     }),
                   std::runtime_error);
    }
    // Every index throws: exactly one exception comes back.
    try {
      pool.parallel_for(50, [](int i) { throw i; });
      ADD_FAILURE() << "no exception";
    } catch (int i) {
      EXPECT_GE(i, 0);
      EXPECT_LT(i, 50);
    }
    // Still usable afterwards.
    std::atomic<int> count{0};
    pool.parallel_for(64, [&](int) { count.fetch_add(1); });
    EXPECT_EQ(count.load(), 64);
  }
}

}  // namespace
// A pool whose threads cannot start (here: every new thread's default stack is larger than the
// address space, so pthread_create fails) reports one line instead of deadlocking; in a child
// process, killed by an alarm if it hangs.
TEST(ThreadPoolDeathTest, StartFailureIsOneLineErrorNotAHang) {
  EXPECT_EXIT(
      {
        alarm(20);
        pthread_attr_t attr;
        pthread_attr_init(&attr);
        pthread_attr_setstacksize(&attr, std::size_t{1} << 50);
        pthread_setattr_default_np(&attr);
        try {
          ThreadPool pool(4);
          std::_Exit(2);  // started: no failure to test
        } catch (const UserError& e) {
          const std::string message = e.what();
          const bool one_line = message.find('\n') == std::string::npos;
          std::_Exit(one_line && message.starts_with("cannot start 4 threads") ? 0 : 3);
        }
      },
      ::testing::ExitedWithCode(0), "");
}

}  // namespace cradle

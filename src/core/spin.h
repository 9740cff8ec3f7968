// Brief polling before a thread sleeps on a condition variable: a wake-up that comes soon after
// then costs no futex round trip, which on a VM costs as much as the typical imbalance between
// two env steps. Shared by the thread pool and the async vector env.
#pragma once

#include <chrono>
#include <thread>

namespace cradle {

// One CPU relax hint (x86 pause, ARM yield) inside a polling loop.
inline void cpu_relax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#elif defined(__aarch64__)
  asm volatile("yield");
#endif
}

// Polls `ready` for up to `budget`; true when it became true (the caller sleeps otherwise).
// The first polls pause the core; later ones yield it (sched_yield), so that a thread which wants
// the core meanwhile (an overlapped PPO update, another process) runs instead of this loop, while a
// wake-up within the budget still needs no futex round trip. On 2 cores, pause-only polling took
// the update's CPU: PPO self-touch with the overlapped update ran 3,259-3,479 env steps/s polling
// 250 us with pauses, 3,626-3,697 with this loop and a 1 ms budget (docs/performance.md).
template <class Ready>
bool spin_until(Ready ready, std::chrono::microseconds budget) {
  constexpr int kPauses = 64;  // about 3 us of pauses before the first yield
  const auto deadline = std::chrono::steady_clock::now() + budget;
  for (int k = 1;; ++k) {
    if (ready()) return true;
    if (k <= kPauses) {
      cpu_relax();
      continue;
    }
    std::this_thread::yield();
    // A yield can last a time slice when another thread runs: the clock is read after each one.
    if (std::chrono::steady_clock::now() > deadline) return ready();
  }
}

}  // namespace cradle

// Brief polling before a thread sleeps on a condition variable: a wake-up that comes soon after
// then costs no futex round trip, which on a VM costs as much as the typical imbalance between
// two env steps. Shared by the thread pool and the async vector env.
#pragma once

#include <chrono>

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
template <class Ready>
bool spin_until(Ready ready, std::chrono::microseconds budget) {
  const auto deadline = std::chrono::steady_clock::now() + budget;
  for (int k = 1;; ++k) {
    if (ready()) return true;
    cpu_relax();
    if (k % 64 == 0 && std::chrono::steady_clock::now() > deadline) return ready();
  }
}

}  // namespace cradle

// Stop signals for long runs: one flag per process, set by a signal handler and read by the
// training loops (their `stop` option), so that a run ends at its next step with a checkpoint.
#pragma once

#include <atomic>
#include <initializer_list>

namespace cradle::apps {

// Routes `signals` (e.g. SIGINT, SIGTERM) to the process's stop flag and returns it.
const std::atomic<bool>* stop_on(std::initializer_list<int> signals);

}  // namespace cradle::apps

// Stop signals for long runs: one flag per process, set by a signal handler and read by the
// training loops (their `stop` option), so that a run ends at its next step with a checkpoint.
#pragma once

#include <atomic>
#include <initializer_list>

namespace cradle::apps {

// Routes `signals` (e.g. SIGINT, SIGTERM) to the process's stop flag and returns it.
const std::atomic<bool>* stop_on(std::initializer_list<int> signals);

// The exit status of a run that a stop signal ended after it saved its checkpoint and reported:
// what a shell reports for a command ended by Ctrl-C. Not 0, so that a campaign launcher, a job
// scheduler or `cradle launch` never takes a stopped run for a finished one.
inline constexpr int kStoppedStatus = 130;

// Thrown by a command once its stopped run has written everything; `main` exits with
// kStoppedStatus. Not a std::exception: it is no error and must not be reported as one.
struct Stopped {};

}  // namespace cradle::apps

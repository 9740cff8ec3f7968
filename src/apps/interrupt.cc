#include "apps/interrupt.h"

#include <csignal>

namespace cradle::apps {
namespace {

// The one piece of process state: a signal handler can only reach a static.
std::atomic<bool> stop_requested{false};
extern "C" void on_stop_signal(int) { stop_requested.store(true); }

}  // namespace

const std::atomic<bool>* stop_on(std::initializer_list<int> signals) {
  for (int signal : signals) std::signal(signal, on_stop_signal);
  return &stop_requested;
}

}  // namespace cradle::apps

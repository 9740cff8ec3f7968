#include "sim/mujoco_handlers.h"

#include <mujoco/mujoco.h>

#include <cstdio>
#include <mutex>
#include <string>

#include "core/error.h"

namespace cradle::sim {
namespace {

// One line: MuJoCo's messages may hold newlines.
std::string one_line(const char* message) {
  std::string text = message ? message : "(no message)";
  for (char& ch : text) {
    if (ch == '\n' || ch == '\r') ch = ' ';
  }
  while (!text.empty() && text.back() == ' ') text.pop_back();
  return text;
}

// MuJoCo is built with unwind tables, so the exception crosses its frames to our caller.
extern "C" void on_mujoco_error(const char* message) {
  throw UserError("MuJoCo: " + one_line(message));
}

extern "C" void on_mujoco_warning(const char* message) {
  std::fprintf(stderr, "cradle: MuJoCo warning: %s\n", one_line(message).c_str());
}

}  // namespace

void install_mujoco_handlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    mju_user_error = on_mujoco_error;
    mju_user_warning = on_mujoco_warning;
  });
}

}  // namespace cradle::sim

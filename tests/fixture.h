// What the tests share: the reference configs, fresh temp folders, shell commands and the `cradle`
// CLI runner (header-only; CRADLE_SOURCE_DIR and CRADLE_BINARY come from CMake).
#pragma once

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <thread>
#include <vector>

#include "core/config.h"

namespace cradle::test {

// configs/<name> of the source tree, e.g. "config_selftouch.yml".
inline std::filesystem::path config_path(const std::string& name) {
  return std::filesystem::path(CRADLE_SOURCE_DIR) / "configs" / name;
}
inline Config reference_config(const std::string& name) { return load_config(config_path(name)); }

// An empty folder <tmp>/cradle_<tag>_<pid>, removed first if a crashed run left it.
inline std::filesystem::path fresh_dir(const std::string& tag) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("cradle_" + tag + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

// A quick self-touch config (crib, no vision, `episode_steps`-step episodes, then `extra` YAML
// lines) in dir/config.yml whose run goes to dir/run; returns the config's path.
inline std::string self_touch_config(const std::filesystem::path& dir, int episode_steps,
                                     const std::string& extra = "") {
  const std::filesystem::path file = dir / "config.yml";
  std::ofstream(file) << "behavior: self_touch\nscene: crib\nsave_dir: " << (dir / "run").string()
                      << "\nvision_active: False\nmax_episode_steps: " << episode_steps << "\n"
                      << extra;
  return file.string();
}

// The lines of a text file, without their '\n' (none when the file cannot be read).
inline std::vector<std::string> read_lines(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

struct RunResult {
  int status = -1;  // exit status (-1: could not run)
  std::string out;  // what it printed on stdout (and stderr when the command merges it)
};

// The message lines of a command's output: without the progress bar (its '[###...]' lines and
// carriage returns) and blank lines.
inline std::vector<std::string> message_lines(const std::string& out) {
  std::vector<std::string> lines;
  size_t at = 0;
  for (size_t end; (end = out.find('\n', at)) != std::string::npos; at = end + 1) {
    std::string line = out.substr(at, end - at);
    const size_t cr = line.rfind('\r');
    if (cr != std::string::npos) line = line.substr(cr + 1);
    if (line.starts_with("[")) continue;  // the progress bar
    if (line.find_first_not_of(' ') != std::string::npos) lines.push_back(line);
  }
  return lines;
}

// Runs a shell command.
inline RunResult run(const std::string& command) {
  RunResult r;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return r;
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, pipe)) > 0) r.out.append(buf, n);
  const int status = ::pclose(pipe);
  r.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

// Runs `cradle <args>` (stdout and stderr together), in `dir` when given.
inline RunResult run_cradle(const std::string& args, const std::filesystem::path& dir = {}) {
  std::string command = std::string(CRADLE_BINARY) + " " + args + " 2>&1";
  if (!dir.empty()) command = "cd '" + dir.string() + "' && " + command;
  return run(command);
}

// Starts `cradle <args>` (output discarded), polls `ready` every 5 ms for up to two minutes, then
// kills it with SIGKILL (whether or not it became ready) and waits for it. Returns whether `ready`
// held: kill -9 at a moment the caller chose, as a crash would.
inline bool run_cradle_then_kill(const std::string& args, const std::function<bool()>& ready) {
  const std::string cmd = "exec " + std::string(CRADLE_BINARY) + " " + args + " >/dev/null 2>&1";
  const pid_t child = ::fork();
  if (child < 0) return false;
  if (child == 0) {
    ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    ::_exit(127);
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  bool seen = false;
  while (!seen && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    seen = ready();
  }
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  return seen;
}

// Starts `cradle <args>`, sends it `signal` (e.g. "INT", "TERM") one second after `ready` exists
// and is not empty, and waits for it to end (stdout and stderr together). A command that
// ignores the signal meets a 5-minute timeout: status 124.
inline RunResult run_cradle_then_signal(const std::string& args, const std::filesystem::path& ready,
                                        const std::string& signal) {
  return run("timeout 300 sh -c '" + std::string(CRADLE_BINARY) + " " + args +
             " & pid=$!; while kill -0 $pid 2>/dev/null && [ ! -s " + ready.string() +
             " ]; do sleep 0.1; done; sleep 1; kill -" + signal + " $pid; wait $pid' 2>&1");
}

}  // namespace cradle::test

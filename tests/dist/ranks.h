// Real processes for the distributed tests: this test binary re-run as a worker (main.cc runs the
// worker named by CRADLE_DIST_WORKER instead of the tests), or any command, each with its own
// environment and its output in a file.
#pragma once

#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace cradle::test {

// A TCP port free right now on loopback.
inline int free_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
  socklen_t size = sizeof a;
  ::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &size);
  ::close(fd);
  return ntohs(a.sin_port);
}

struct Process {
  pid_t pid = -1;
  std::filesystem::path log;
  int status = -1;  // exit code once waited for; 128 + signal when killed

  std::string output() const {
    std::ifstream in(log);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
};

// Starts argv with `env` added to this process's environment; stdout and stderr go to `log`.
inline Process spawn(const std::vector<std::string>& argv,
                     const std::map<std::string, std::string>& env,
                     const std::filesystem::path& log) {
  Process p{.log = log};
  p.pid = ::fork();
  if (p.pid == 0) {
    for (const auto& [name, value] : env) ::setenv(name.c_str(), value.c_str(), 1);
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(fd, 1);
    ::dup2(fd, 2);
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    ::execv(args[0], args.data());
    ::_exit(127);
  }
  return p;
}

// This binary as worker `name` of rank `rank` in a world of `world` on `port`.
inline Process spawn_worker(const std::string& name, int rank, int world, int port,
                            const std::filesystem::path& dir,
                            std::map<std::string, std::string> env = {}) {
  env["CRADLE_DIST_WORKER"] = name;
  env["RANK"] = std::to_string(rank);
  env["WORLD_SIZE"] = std::to_string(world);
  env["MASTER_ADDR"] = "127.0.0.1";
  env["MASTER_PORT"] = std::to_string(port);
  env["CRADLE_DIST_DIR"] = dir.string();
  const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
  return spawn({self}, env, dir / (name + "_rank" + std::to_string(rank) + ".log"));
}

// Waits for p (killing it after `seconds`); returns its status.
inline int wait_for(Process& p, double seconds = 60) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  int status = 0;
  while (::waitpid(p.pid, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      ::kill(p.pid, SIGKILL);
      ::waitpid(p.pid, &status, 0);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  p.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return p.status;
}

}  // namespace cradle::test

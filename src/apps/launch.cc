// `cradle launch --nproc N [--master-port P] -- cradle train ...`: one machine's torchrun. Starts N
// ranks of the command with WORLD_SIZE, RANK, LOCAL_RANK, LOCAL_WORLD_SIZE, MASTER_ADDR and
// MASTER_PORT set (and --distributed added to `cradle train`), forwards SIGINT and SIGTERM to them,
// and when one fails stops the others and exits non-zero naming it. Stopped by a signal, it exits
// 130 once the ranks have saved.
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "apps/cli_checks.h"
#include "apps/commands.h"
#include "apps/interrupt.h"
#include "core/error.h"

namespace cradle::apps {
namespace {

// The signal to forward (0: none), set by the handler: the one piece of process state.
std::atomic<int> forwarded{0};
extern "C" void on_forward(int signal) { forwarded.store(signal); }

// A TCP port that is free on this machine now (the kernel's pick).
int free_port() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_ANY);
  socklen_t size = sizeof a;
  const bool ok = fd >= 0 && bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0 &&
                  getsockname(fd, reinterpret_cast<sockaddr*>(&a), &size) == 0;
  if (fd >= 0) close(fd);
  if (!ok) throw UserError("cradle launch: no free port for the master (give --master-port)");
  return ntohs(a.sin_port);
}

std::string describe(int status) {
  if (WIFSIGNALED(status)) {
    return std::string("was killed by signal ") + std::to_string(WTERMSIG(status)) + " (" +
           strsignal(WTERMSIG(status)) + ")";
  }
  return "exited with status " + std::to_string(WEXITSTATUS(status));
}

struct Rank {
  pid_t pid = -1;
  bool running = false;
};

int launch(int nproc, int port, const std::string& addr, double grace,
           std::vector<std::string> command) {
  if (command.empty()) {
    throw UserError("cradle launch: expected a command after --, e.g. -- cradle train --config F");
  }
  // `cradle ...` runs this very binary; `cradle train` gets --distributed.
  if (command[0] == "cradle") command[0] = std::filesystem::read_symlink("/proc/self/exe");
  const bool train = command.size() > 1 && command[1] == "train";
  if (train && std::find(command.begin(), command.end(), "--distributed") == command.end()) {
    command.insert(command.begin() + 2, "--distributed");
  }
  if (port == 0) port = free_port();

  struct sigaction action {};
  action.sa_handler = on_forward;
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);

  // Start every rank with the rendezvous in its environment. SIGINT and SIGTERM stay blocked
  // across fork: a child that got one before its exec would run our forwarding handler and live
  // on; it resets them to the default first, so a pending stop ends it as soon as it unblocks.
  sigset_t stops, previous;
  sigemptyset(&stops);
  sigaddset(&stops, SIGINT);
  sigaddset(&stops, SIGTERM);
  sigprocmask(SIG_BLOCK, &stops, &previous);
  std::vector<Rank> ranks(nproc);
  for (int r = 0; r < nproc; ++r) {
    const pid_t pid = fork();
    if (pid < 0) {
      sigprocmask(SIG_SETMASK, &previous, nullptr);
      throw UserError("cradle launch: cannot start rank " + std::to_string(r));
    }
    if (pid == 0) {
      signal(SIGINT, SIG_DFL);
      signal(SIGTERM, SIG_DFL);
      sigprocmask(SIG_SETMASK, &previous, nullptr);
      setenv("WORLD_SIZE", std::to_string(nproc).c_str(), 1);
      setenv("RANK", std::to_string(r).c_str(), 1);
      setenv("LOCAL_RANK", std::to_string(r).c_str(), 1);
      setenv("LOCAL_WORLD_SIZE", std::to_string(nproc).c_str(), 1);
      setenv("MASTER_ADDR", addr.c_str(), 1);
      setenv("MASTER_PORT", std::to_string(port).c_str(), 1);
      std::vector<char*> argv;
      for (std::string& a : command) argv.push_back(a.data());
      argv.push_back(nullptr);
      execvp(argv[0], argv.data());
      std::fprintf(stderr, "cradle launch: cannot run '%s': %s\n", argv[0], std::strerror(errno));
      _exit(127);
    }
    ranks[r] = {.pid = pid, .running = true};
  }
  sigprocmask(SIG_SETMASK, &previous, nullptr);
  std::fprintf(stderr, "cradle launch: %d ranks, master %s:%d\n", nproc, addr.c_str(), port);

  // Wait for them; forward signals; the first failure stops the rest.
  int failed = -1, failed_status = 0, running = nproc;
  bool stop_forwarded = false, stopped = false;
  auto stop_others = [&](int signal) {
    for (const Rank& rank : ranks) {
      if (rank.running) kill(rank.pid, signal);
    }
  };
  std::chrono::steady_clock::time_point kill_at = std::chrono::steady_clock::time_point::max();
  while (running > 0) {
    if (const int signal = forwarded.exchange(0)) {
      stop_forwarded = true;
      stop_others(signal);
    }
    int status = 0;
    const pid_t pid = waitpid(-1, &status, WNOHANG);
    if (pid > 0) {
      const auto it =
          std::find_if(ranks.begin(), ranks.end(), [pid](const Rank& r) { return r.pid == pid; });
      if (it == ranks.end()) continue;
      it->running = false;
      --running;
      const bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 0;
      // After a forwarded stop, a rank that saved its checkpoint and exited 130 did as asked.
      const bool saved =
          stop_forwarded && WIFEXITED(status) && WEXITSTATUS(status) == kStoppedStatus;
      stopped = stopped || saved;
      if (!ok && !saved && failed < 0) {
        failed = static_cast<int>(it - ranks.begin());
        failed_status = status;
        if (running > 0) {
          std::fprintf(stderr, "cradle launch: rank %d %s; stopping the other ranks\n", failed,
                       describe(status).c_str());
          stop_others(SIGTERM);
          kill_at = std::chrono::steady_clock::now() +
                    std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                        std::chrono::duration<double>(grace));
        }
      }
      continue;
    }
    // Ranks that outlive the grace period after a failure are killed.
    if (std::chrono::steady_clock::now() > kill_at) {
      stop_others(SIGKILL);
      kill_at = std::chrono::steady_clock::time_point::max();
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (failed >= 0) {
    throw UserError("rank " + std::to_string(failed) + " " + describe(failed_status) +
                    " (the job can resume from its last checkpoint with --resume)");
  }
  if (stopped) {
    std::fprintf(stderr,
                 "cradle launch: stopped by a signal; the ranks saved their checkpoint: the same "
                 "command with --resume continues\n");
    throw Stopped{};
  }
  return 0;
}

}  // namespace

void register_launch(CLI::App& app) {
  struct Options {
    int nproc = 1;
    int port = 0;
    std::string addr = "127.0.0.1";
    double grace = 30;
    std::vector<std::string> command;
  };
  auto opts = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "launch",
      "Run N ranks of a command on this machine (torchrun): launch --nproc N -- cradle train ...");
  cmd->add_option("--nproc", opts->nproc, "Ranks (processes) to start")
      ->required()
      ->check(CLI::Range(1, 4096));
  cmd->add_option("--master-port", opts->port, "Rank 0's port (0: a free one)")
      ->check(CLI::Range(0, 65535));
  cmd->add_option("--master-addr", opts->addr, "Rank 0's address");
  cmd->add_option("--grace", opts->grace,
                  "Seconds the other ranks get to stop after one fails before they are killed")
      ->check(kFinite)
      ->check(CLI::Range(0.0, 3600.0));
  cmd->add_option("command", opts->command, "The command after --, e.g. cradle train ...");
  cmd->callback([opts] {
    const int code = launch(opts->nproc, opts->port, opts->addr, opts->grace, opts->command);
    if (code != 0) std::exit(code);
  });
}

}  // namespace cradle::apps

#include "dist/process_group.h"

#include <arpa/inet.h>
#include <netdb.h>
#include <sys/socket.h>
#include <unistd.h>

// Gloo's half of c10d (Torch's CMake package defines it too).
#ifndef USE_C10D_GLOO
#define USE_C10D_GLOO 1
#endif
#include <torch/torch.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <torch/csrc/distributed/c10d/ProcessGroupGloo.hpp>
#include <torch/csrc/distributed/c10d/TCPStore.hpp>
#include <vector>

#include "core/error.h"

namespace cradle::dist {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

// Store keys, all under one prefix.
std::string key(const std::string& what, int rank) {
  return "cradle/" + what + "/" + std::to_string(rank);
}
std::vector<std::uint8_t> bytes(const std::string& text) { return {text.begin(), text.end()}; }
std::string text(const std::vector<std::uint8_t>& bytes) { return {bytes.begin(), bytes.end()}; }

// The error's first line (c10 errors append a C++ stack trace).
std::string first_line(const std::string& message) { return message.substr(0, message.find('\n')); }

std::string address(const Rendezvous& r) {
  return r.master_addr + ":" + std::to_string(r.master_port);
}

// This host's address on the route to the master, which the other ranks can reach it at (a UDP
// "connect" sends nothing; it only picks the route). Loopback for a master on this host.
std::string local_address_towards(const Rendezvous& r) {
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_DGRAM;
  addrinfo* found = nullptr;
  if (getaddrinfo(r.master_addr.c_str(), std::to_string(r.master_port).c_str(), &hints, &found) !=
          0 ||
      found == nullptr) {
    throw UserError("cannot resolve the master address '" + r.master_addr +
                    "' (MASTER_ADDR / --master): expected a host name or IPv4 address");
  }
  std::string local = "127.0.0.1";
  const int fd = socket(AF_INET, SOCK_DGRAM, 0);
  if (fd >= 0 && connect(fd, found->ai_addr, found->ai_addrlen) == 0) {
    sockaddr_in self{};
    socklen_t size = sizeof self;
    char buf[INET_ADDRSTRLEN] = {};
    if (getsockname(fd, reinterpret_cast<sockaddr*>(&self), &size) == 0 &&
        inet_ntop(AF_INET, &self.sin_addr, buf, sizeof buf) != nullptr) {
      local = buf;
    }
  }
  if (fd >= 0) close(fd);
  freeaddrinfo(found);
  return local;
}

c10d::ReduceOp reduce_op(Reduce op) {
  switch (op) {
    case Reduce::kMax:
      return c10d::ReduceOp::MAX;
    case Reduce::kMin:
      return c10d::ReduceOp::MIN;
    default:
      return c10d::ReduceOp::SUM;
  }
}

// A store client of its own that bumps this rank's counter every kBeat, so that a survivor can
// tell a dead rank (its counter stops) from a slow one.
constexpr milliseconds kBeat{500};
constexpr milliseconds kDeadAfter{2000};

class Heartbeat {
 public:
  Heartbeat(const Rendezvous& r, c10::intrusive_ptr<c10d::Store> store)
      : store_(std::move(store)), key_(key("beat", r.rank)) {
    thread_ = std::thread([this] { run(); });
  }
  ~Heartbeat() {
    {
      const std::lock_guard lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    thread_.join();
  }

 private:
  void run() {
    std::unique_lock lock(mutex_);
    while (!stop_) {
      try {
        store_->add(key_, 1);
      } catch (const std::exception&) {
        return;  // the master is gone: the collectives will say so
      }
      wake_.wait_for(lock, kBeat, [this] { return stop_; });
    }
  }

  c10::intrusive_ptr<c10d::Store> store_;
  const std::string key_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stop_ = false;
  std::thread thread_;
};

}  // namespace

struct ProcessGroup::State {
  Rendezvous r;
  c10::intrusive_ptr<c10d::TCPStore> store;
  std::unique_ptr<Heartbeat> heartbeat;
  c10::intrusive_ptr<c10d::ProcessGroupGloo> group;
  double seconds = 0;
  long count = 0;

  // A store client (rank 0 also starts the server), with one-line errors.
  c10::intrusive_ptr<c10d::TCPStore> connect(bool server) const {
    c10d::TCPStoreOptions options;
    options.port = static_cast<std::uint16_t>(r.master_port);
    options.isServer = server;
    options.numWorkers = r.world_size;
    options.waitWorkers = false;
    options.timeout = std::chrono::seconds(r.timeout_seconds);
    try {
      return c10::make_intrusive<c10d::TCPStore>(r.master_addr, options);
    } catch (const std::exception& e) {
      if (server) {
        throw UserError("rank 0 cannot listen on " + address(r) +
                        " (another run on that port? set MASTER_PORT or --master-port): " +
                        first_line(e.what()));
      }
      throw UserError("rank " + std::to_string(r.rank) + " cannot reach the master at " +
                      address(r) + " within " + std::to_string(r.timeout_seconds) +
                      " s (is rank 0 running? MASTER_ADDR / MASTER_PORT / --master)");
    }
  }

  // Marks this rank refused and throws.
  [[noreturn]] void refuse(const std::string& message) {
    try {
      store->set(key("bad", r.rank), bytes(message));
    } catch (const std::exception&) {
    }
    throw UserError(message);
  }

  // Every rank present with the same world size, none twice; then every rank's verdict.
  void check_world() {
    const std::string rank_text = std::to_string(r.rank);
    if (store->add(key("joined", r.rank), 1) != 1) {
      throw UserError("rank " + rank_text + " joined twice (two processes with RANK=" + rank_text +
                      ")");
    }
    store->set(key("world", r.rank), bytes(std::to_string(r.world_size)));
    const auto deadline = Clock::now() + std::chrono::seconds(r.timeout_seconds);
    for (const char* phase : {"world", "ok"}) {
      std::vector<bool> seen(r.world_size, false);
      int missing = r.world_size;
      while (missing > 0) {
        for (int i = 0; i < r.world_size; ++i) {
          if (seen[i]) continue;
          if (store->check({key("bad", i)}) && i != r.rank) {
            throw UserError("rank " + std::to_string(i) +
                            " refused to join: " + text(store->get(key("bad", i))));
          }
          if (!store->check({key(phase, i)})) continue;
          seen[i] = true;
          --missing;
          if (std::string(phase) == "world") {
            const std::string theirs = text(store->get(key("world", i)));
            if (theirs != std::to_string(r.world_size)) {
              refuse("world sizes differ: rank " + std::to_string(i) + " has WORLD_SIZE=" + theirs +
                     ", rank " + rank_text + " " + std::to_string(r.world_size));
            }
          }
        }
        if (missing == 0) break;
        if (Clock::now() > deadline) {
          std::string absent;
          for (int i = 0; i < r.world_size; ++i) {
            if (!seen[i]) absent += (absent.empty() ? "" : ", ") + std::to_string(i);
          }
          refuse("rank(s) " + absent + " of " + std::to_string(r.world_size) +
                 " did not join within " + std::to_string(r.timeout_seconds) + " s at " +
                 address(r));
        }
        std::this_thread::sleep_for(milliseconds(20));
      }
      if (std::string(phase) == "world") store->set(key("ok", r.rank), bytes("1"));
    }
  }

  // Why a collective failed, in one line: a rank's own announcement, a rank whose heartbeat
  // stopped, or the master gone.
  std::string diagnose(const std::string& what) {
    try {
      std::vector<std::int64_t> before(r.world_size), after(r.world_size);
      for (int i = 0; i < r.world_size; ++i) before[i] = store->add(key("beat", i), 0);
      const auto until = Clock::now() + kDeadAfter;
      while (Clock::now() < until) {
        for (int i = 0; i < r.world_size; ++i) {
          if (i != r.rank && store->check({key("failed", i)})) {
            return "rank " + std::to_string(i) + " stopped: " + text(store->get(key("failed", i)));
          }
        }
        std::this_thread::sleep_for(milliseconds(100));
      }
      std::string dead;
      for (int i = 0; i < r.world_size; ++i) {
        after[i] = store->add(key("beat", i), 0);
        if (i != r.rank && after[i] == before[i]) {
          dead += (dead.empty() ? "" : ", ") + std::to_string(i);
        }
      }
      if (!dead.empty()) {
        return "rank " + dead + " died (no heartbeat for " +
               std::to_string(kDeadAfter.count() / 1000) + " s)";
      }
      return "a collective failed while every rank is alive: " + first_line(what);
    } catch (const std::exception&) {
      return "rank 0 died (the master at " + address(r) + " is gone)";
    }
  }

  // Runs a collective, timed; a failure becomes a UserError naming the rank at fault.
  void run(const std::function<c10::intrusive_ptr<c10d::Work>()>& start) {
    const auto begin = Clock::now();
    try {
      start()->wait();
    } catch (const std::exception& e) {
      throw UserError("rank " + std::to_string(r.rank) + ": distributed run stopped: " +
                      diagnose(e.what()) + " (resume the job from its last checkpoint)");
    }
    seconds += std::chrono::duration<double>(Clock::now() - begin).count();
    ++count;
  }

  template <typename T>
  void all_reduce(std::span<T> values, Reduce op) {
    if (values.empty() || r.world_size == 1) return;
    std::vector<at::Tensor> tensors{
        torch::from_blob(values.data(), {static_cast<long>(values.size())},
                         std::is_same_v<T, float> ? torch::kFloat32 : torch::kFloat64)};
    c10d::AllreduceOptions options;
    options.reduceOp = reduce_op(op);
    run([&] { return group->allreduce(tensors, options); });
  }

  template <typename T>
  void broadcast(std::span<T> values, int root) {
    if (values.empty() || r.world_size == 1) return;
    std::vector<at::Tensor> tensors{
        torch::from_blob(values.data(), {static_cast<long>(values.size())},
                         std::is_same_v<T, float> ? torch::kFloat32 : torch::kFloat64)};
    c10d::BroadcastOptions options;
    options.rootRank = root;
    run([&] { return group->broadcast(tensors, options); });
  }
};

ProcessGroup::ProcessGroup(const Rendezvous& r) : state_(std::make_unique<State>()) {
  State& s = *state_;
  s.r = r;
  if (r.world_size == 1) return;  // alone: every collective is the identity
  const std::string local = local_address_towards(r);
  s.store = s.connect(r.rank == 0);
  s.check_world();
  s.heartbeat = std::make_unique<Heartbeat>(r, s.connect(false));
  try {
    auto options = c10d::ProcessGroupGloo::Options::create(std::chrono::seconds(r.timeout_seconds));
    options->devices.push_back(c10d::ProcessGroupGloo::createDeviceForHostname(local));
    options->threads = 1;
    s.group = c10::make_intrusive<c10d::ProcessGroupGloo>(s.store, r.rank, r.world_size, options);
  } catch (const std::exception& e) {
    throw UserError("rank " + std::to_string(r.rank) + " could not connect to the other ranks (" +
                    local + " as its address): " + first_line(e.what()));
  }
}

ProcessGroup::~ProcessGroup() {
  State& s = *state_;
  s.heartbeat.reset();
  s.group.reset();
  s.store.reset();
}

int ProcessGroup::rank() const { return state_->r.rank; }
int ProcessGroup::world_size() const { return state_->r.world_size; }
const Rendezvous& ProcessGroup::rendezvous() const { return state_->r; }

void ProcessGroup::all_reduce(std::span<float> values, Reduce op) {
  state_->all_reduce(values, op);
}
void ProcessGroup::all_reduce(std::span<double> values, Reduce op) {
  state_->all_reduce(values, op);
}
void ProcessGroup::broadcast(std::span<float> values, int root) { state_->broadcast(values, root); }
void ProcessGroup::broadcast(std::span<double> values, int root) {
  state_->broadcast(values, root);
}

void ProcessGroup::barrier() {
  if (state_->r.world_size == 1) return;
  state_->run([&] { return state_->group->barrier(); });
}

void ProcessGroup::announce_failure(const std::string& message) noexcept {
  if (!state_->store) return;
  try {
    state_->store->set(key("failed", state_->r.rank), bytes(first_line(message)));
  } catch (...) {
  }
}

double ProcessGroup::collective_seconds() const { return state_->seconds; }
long ProcessGroup::collectives() const { return state_->count; }

}  // namespace cradle::dist

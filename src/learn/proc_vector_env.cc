#include "learn/proc_vector_env.h"

#include <semaphore.h>
#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <exception>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <system_error>
#include <thread>
#include <utility>

#include "core/error.h"
#include "core/spin.h"
#include "envs/action_check.h"
#include "learn/vector_env.h"

namespace cradle::learn {
namespace {

// The shared block: one control area per worker, the batch arrays, then one slot per env. Pages
// are only backed once touched (MAP_NORESERVE), so the generous slot costs what an env uses.
constexpr size_t kControlBytes = size_t{64} << 10;
constexpr size_t kPayloadOffset = 4096;  // within a control area: a command's arguments
constexpr size_t kEnvSlotBytes = size_t{64} << 20;
constexpr size_t kAlign = 64;

size_t round_up(size_t n, size_t to) { return (n + to - 1) / to * to; }

// Takes the semaphore if it is posted within a millisecond, polling (and yielding the core) the
// while; false: the caller sleeps on it. A worker's next command and a step's end mostly come
// that soon, and sem_post wakes no one in the kernel when nobody sleeps on the semaphore.
bool take_soon(sem_t& semaphore) {
  return spin_until([&] { return sem_trywait(&semaphore) == 0; }, std::chrono::microseconds{1000});
}

enum Command : std::int32_t { kBuild, kReset, kStep, kResetEnded, kOptions, kClose, kCall, kStop };
enum Status : std::int32_t { kOk, kUserError, kInvalidArgument, kOtherError };

struct Control {
  sem_t go, done;
  std::int32_t command = 0, arg = 0, status = 0;
  char error[1024] = {};
};

struct EnvHeader {
  std::int32_t steps = 0;
  std::uint32_t list_bytes = 0;     // info lists at the start of the variable area
  std::uint32_t message_bytes = 0;  // the outbox's bytes after them
};

// Where an env's values sit in its slot; the same for every env of a vector, computed from the
// spaces and the info keys by the worker and by the parent alike.
struct SlotLayout {
  size_t actions = 0, header = 0, numbers = 0, observation = 0, variable = 0, variable_bytes = 0;
  SlotLayout() = default;
  SlotLayout(int action_size, int info_keys, size_t observation_bytes) {
    header = round_up(sizeof(double) * action_size, kAlign);
    numbers = header + round_up(sizeof(EnvHeader), kAlign);
    observation = numbers + round_up(sizeof(double) * info_keys, kAlign);
    variable = observation + round_up(observation_bytes, kAlign);
    if (variable >= kEnvSlotBytes) {
      throw UserError("an env's observation takes " + std::to_string(observation_bytes >> 20) +
                      " MiB, more than a process vector's " + std::to_string(kEnvSlotBytes >> 20) +
                      " MiB per env; use threads");
    }
    variable_bytes = kEnvSlotBytes - variable;
  }
};

// Bytes in, bytes out: an env's description and a command's arguments.
class Writer {
 public:
  Writer(std::byte* data, size_t capacity, const char* what)
      : data_(data), capacity_(capacity), what_(what) {}
  void raw(const void* p, size_t n) {
    if (size_ + n > capacity_) {
      throw UserError(std::string(what_) + " needs more than " + std::to_string(capacity_) +
                      " bytes of a process vector's shared memory");
    }
    std::memcpy(data_ + size_, p, n);
    size_ += n;
  }
  template <typename T>
  void put(T v) {
    raw(&v, sizeof v);
  }
  void str(std::string_view s) {
    put<std::uint32_t>(s.size());
    raw(s.data(), s.size());
  }
  template <typename T>
  void list(const std::vector<T>& v) {
    put<std::uint32_t>(v.size());
    raw(v.data(), v.size() * sizeof(T));
  }
  size_t size() const { return size_; }

 private:
  std::byte* data_;
  size_t capacity_, size_ = 0;
  const char* what_;
};

class Reader {
 public:
  Reader(const std::byte* data, size_t size) : data_(data), size_(size) {}
  void raw(void* p, size_t n) {
    if (at_ + n > size_) throw std::runtime_error("process vector: truncated message");
    std::memcpy(p, data_ + at_, n);
    at_ += n;
  }
  template <typename T>
  T get() {
    T v;
    raw(&v, sizeof v);
    return v;
  }
  std::string str() {
    std::string s(get<std::uint32_t>(), '\0');
    raw(s.data(), s.size());
    return s;
  }
  template <typename T>
  std::vector<T> list() {
    std::vector<T> v(get<std::uint32_t>());
    raw(v.data(), v.size() * sizeof(T));
    return v;
  }

 private:
  const std::byte* data_;
  size_t size_, at_ = 0;
};

void put_box(Writer& w, const Box& box) {
  w.list(box.shape);
  w.put<std::int32_t>(static_cast<std::int32_t>(box.dtype));
  w.list(box.low);
  w.list(box.high);
}

Box get_box(Reader& r) {
  Box box;
  box.shape = r.list<int>();
  box.dtype = static_cast<DType>(r.get<std::int32_t>());
  box.low = r.list<double>();
  box.high = r.list<double>();
  return box;
}

// What the parent needs to stand in for an env: spaces, info keys and layouts.
void describe(const envs::Env& env, Writer& w) {
  const DictSpace& space = env.observation_space();
  w.put<std::uint32_t>(space.entries.size());
  for (const auto& [key, box] : space.entries) {
    w.str(key);
    put_box(w, box);
  }
  put_box(w, env.action_space());
  const envs::Info& info = env.info();
  w.put<std::int32_t>(info.size());
  for (int k = 0; k < info.size(); ++k) {
    w.str(info.name(k));
    w.put<std::int32_t>(static_cast<std::int32_t>(info.type(k)));
    w.put<std::uint8_t>(info.published(k));
  }
  for (const auto& [key, box] : space.entries) {
    const envs::ObservationLayout* layout = env.layout(key);
    w.put<std::uint8_t>(layout != nullptr);
    if (!layout) continue;
    w.put<std::int32_t>(layout->values_per_item);
    w.put<std::uint32_t>(layout->groups.size());
    for (const auto& [name, ids] : layout->groups) {
      w.str(name);
      w.list(ids);
    }
  }
}

struct Description {
  DictSpace observation_space;
  Box action_space;
  struct Key {
    std::string name;
    envs::InfoType type;
    bool published;
  };
  std::vector<Key> info;
  std::map<std::string, envs::ObservationLayout, std::less<>> layouts;
};

Description parse_description(Reader& r) {
  Description d;
  const auto keys = r.get<std::uint32_t>();
  for (std::uint32_t k = 0; k < keys; ++k) {
    std::string key = r.str();
    d.observation_space.entries.emplace_back(std::move(key), get_box(r));
  }
  d.action_space = get_box(r);
  const auto info_keys = r.get<std::int32_t>();
  for (int k = 0; k < info_keys; ++k) {
    std::string name = r.str();
    const auto type = static_cast<envs::InfoType>(r.get<std::int32_t>());
    d.info.push_back({std::move(name), type, r.get<std::uint8_t>() != 0});
  }
  for (const auto& [key, box] : d.observation_space.entries) {
    if (!r.get<std::uint8_t>()) continue;
    envs::ObservationLayout layout;
    layout.values_per_item = r.get<std::int32_t>();
    const auto groups = r.get<std::uint32_t>();
    for (std::uint32_t g = 0; g < groups; ++g) {
      std::string name = r.str();
      layout.groups[std::move(name)] = r.list<int>();
    }
    d.layouts[key] = std::move(layout);
  }
  return d;
}

void copy_error(Control& c, Status status, const char* what) {
  c.status = status;
  std::snprintf(c.error, sizeof c.error, "%s", what);
}

// Runs `fn`, turning its exception into the control area's status and message.
template <typename Fn>
void guarded(Control& c, Fn&& fn) {
  c.status = kOk;
  try {
    fn();
  } catch (const UserError& e) {
    copy_error(c, kUserError, e.what());
  } catch (const std::invalid_argument& e) {
    copy_error(c, kInvalidArgument, e.what());
  } catch (const std::exception& e) {
    copy_error(c, kOtherError, e.what());
  } catch (...) {
    copy_error(c, kOtherError, "unknown error");
  }
}

}  // namespace

// The mapping and typed views into it; the same addresses in the parent and its workers.
struct ProcVecEnv::Shared {
  std::byte* base = nullptr;
  size_t bytes = 0;
  int workers = 0, envs = 0;
  size_t batch = 0, slots = 0;
  SlotLayout layout;

  Shared(int workers_, int envs_) : workers(workers_), envs(envs_) {
    batch = static_cast<size_t>(workers) * kControlBytes;
    const size_t n = envs;
    const size_t batch_bytes = round_up(n * (3 * sizeof(double) + 2), 4096);
    slots = batch + batch_bytes;
    bytes = slots + n * kEnvSlotBytes;
    void* p = mmap(nullptr, bytes, PROT_READ | PROT_WRITE,
                   MAP_SHARED | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
    if (p == MAP_FAILED) {
      throw UserError("cannot map " + std::to_string(bytes >> 20) +
                      " MiB of shared memory for a process vector: " + std::strerror(errno));
    }
    base = static_cast<std::byte*>(p);
    for (int w = 0; w < workers; ++w) {
      Control* c = new (base + w * kControlBytes) Control;
      sem_init(&c->go, 1, 0);
      sem_init(&c->done, 1, 0);
    }
  }
  ~Shared() {
    for (int w = 0; w < workers; ++w) {
      sem_destroy(&control(w).go);
      sem_destroy(&control(w).done);
    }
    munmap(base, bytes);
  }
  Shared(const Shared&) = delete;
  Shared& operator=(const Shared&) = delete;

  Control& control(int w) { return *reinterpret_cast<Control*>(base + w * kControlBytes); }
  std::byte* payload(int w) { return base + w * kControlBytes + kPayloadOffset; }
  static constexpr size_t payload_bytes() { return kControlBytes - kPayloadOffset; }
  std::uint64_t* seeds() { return reinterpret_cast<std::uint64_t*>(base + batch); }
  double* rewards() { return reinterpret_cast<double*>(base + batch) + envs; }
  double* scores() { return reinterpret_cast<double*>(base + batch) + 2 * envs; }
  std::uint8_t* terminated() { return reinterpret_cast<std::uint8_t*>(scores() + envs); }
  std::uint8_t* truncated() { return terminated() + envs; }
  std::byte* slot(int env) { return base + slots + env * kEnvSlotBytes; }
  double* actions(int env) { return reinterpret_cast<double*>(slot(env) + layout.actions); }
  EnvHeader& header(int env) { return *reinterpret_cast<EnvHeader*>(slot(env) + layout.header); }
  double* numbers(int env) { return reinterpret_cast<double*>(slot(env) + layout.numbers); }
  std::span<std::byte> observation(int env, size_t size) {
    return {slot(env) + layout.observation, size};
  }
  std::byte* variable(int env) { return slot(env) + layout.variable; }
};

// env(i) in this process: the worker's values, read from the shared block.
class ProcVecEnv::Proxy final : public envs::Env {
 public:
  Proxy(ProcVecEnv& vec, int id, const Description& d)
      : vec_(vec),
        id_(id),
        observation_(d.observation_space,
                     vec.shared_->observation(
                         id, envs::ObservationBuffers::bytes_needed(d.observation_space))),
        layouts_(d.layouts) {
    for (const Description::Key& key : d.info) info_.declare(key.name, key.type, key.published);
  }
  const DictSpace& observation_space() const override { return vec_.observation_space(); }
  const Box& action_space() const override { return vec_.action_space(); }
  void reset(std::optional<std::uint64_t>) override { not_here("reset"); }
  envs::StepResult step(std::span<const double>) override {
    not_here("step");
    return {};
  }
  const envs::ObservationBuffers& observation() const override { return observation_; }
  const envs::Info& info() const override { return info_; }
  envs::Info& mutable_info() { return info_; }
  void set_reset_options(const envs::ResetOptions& options) override {
    vec_.throw_if_broken();
    const int w = vec_.worker_of(id_);
    Writer out(vec_.shared_->payload(w), Shared::payload_bytes(), "the reset options");
    out.put<std::uint32_t>(options.size());
    for (const auto& [name, value] : options) {
      out.str(name);
      out.put<double>(value);
    }
    vec_.run_one(w, kOptions, id_);
  }
  void close() override {
    vec_.throw_if_broken();
    vec_.run_one(vec_.worker_of(id_), kClose, id_);
  }
  double score() const override { return vec_.shared_->scores()[id_]; }
  const envs::ObservationLayout* layout(std::string_view key) const override {
    const auto it = layouts_.find(key);
    return it == layouts_.end() ? nullptr : &it->second;
  }

 private:
  [[noreturn]] void not_here(const char* what) const {
    throw std::logic_error(std::string("env ") + std::to_string(id_) +
                           " of a process vector runs in its worker: " + what +
                           " it through the vector");
  }
  ProcVecEnv& vec_;
  int id_;
  envs::ObservationBuffers observation_;
  envs::Info info_;
  std::map<std::string, envs::ObservationLayout, std::less<>> layouts_;
};

namespace {

// A worker's side: its envs, built from the factory in this process, and the command loop.
class WorkerLoop {
 public:
  WorkerLoop(ProcVecEnv::Shared& shm, int w, int first, int last,
             const ProcVecEnv::Channels& channels)
      : shm_(shm), w_(w), c_(shm.control(w)), first_(first), last_(last), channels_(channels) {}

  [[noreturn]] void run(const ProcVecEnv::EnvFactory& make) {
    guarded(c_, [&] { build(make); });
    sem_post(&c_.done);
    if (c_.status != kOk) _exit(1);
    for (;;) {
      if (!take_soon(c_.go)) {
        while (sem_wait(&c_.go) != 0) {
        }
      }
      const int command = c_.command;
      guarded(c_, [&] { execute(command); });
      if (command == kStop) {
        sem_post(&c_.done);
        // No destructors or atexit handlers: they belong to the parent's objects.
        _exit(0);
      }
      sem_post(&c_.done);
    }
  }

 private:
  void build(const ProcVecEnv::EnvFactory& make) {
    for (int i = first_; i < last_; ++i) {
      std::unique_ptr<envs::Env> env = make(i);
      if (!env)
        throw std::invalid_argument("ProcVecEnv: the factory gave env " + std::to_string(i) +
                                    " as null");
      // The description, ahead of its length, at the start of the env's slot.
      Writer w(shm_.slot(i) + sizeof(std::uint64_t), kEnvSlotBytes - sizeof(std::uint64_t),
               "an env's description");
      describe(*env, w);
      const std::uint64_t size = w.size();
      std::memcpy(shm_.slot(i), &size, sizeof size);
      envs_.push_back(std::move(env));
    }
    const envs::Env& env = *envs_[0];
    observation_bytes_ = envs::ObservationBuffers::bytes_needed(env.observation_space());
    shm_.layout = SlotLayout(env.action_space().size(), env.info().size(), observation_bytes_);
    action_size_ = env.action_space().size();
    ended_.assign(envs_.size(), 0);
    outbox_.resize(envs_.size());
    for (int i = first_; i < last_; ++i) {
      views_.emplace_back(env.observation_space(), shm_.observation(i, observation_bytes_));
    }
  }

  void execute(int command) {
    const int n = last_ - first_;
    switch (command) {
      case kReset:
        for (int j = 0; j < n; ++j) {
          envs_[j]->reset(shm_.seeds()[first_ + j]);
          finish(j, {}, false);
        }
        break;
      case kStep:
        for (int j = 0; j < n; ++j) {
          const int i = first_ + j;
          // Next-step autoreset: an env that ended last call starts its next episode instead.
          if (ended_[j]) {
            envs_[j]->reset();
            finish(j, {}, false);
            continue;
          }
          finish(j, envs_[j]->step({shm_.actions(i), static_cast<size_t>(action_size_)}), true);
        }
        break;
      case kResetEnded:
        for (int j = 0; j < n; ++j) {
          if (!ended_[j]) continue;
          envs_[j]->reset();
          ended_[j] = 0;
          export_state(j);
        }
        break;
      case kOptions: {
        Reader r(shm_.payload(w_), ProcVecEnv::Shared::payload_bytes());
        envs::ResetOptions options;
        const auto count = r.get<std::uint32_t>();
        for (std::uint32_t k = 0; k < count; ++k) {
          std::string name = r.str();
          options[std::move(name)] = r.get<double>();
        }
        envs_[c_.arg - first_]->set_reset_options(options);
        break;
      }
      case kClose:
        envs_[c_.arg - first_]->close();
        break;
      case kCall:
        for (int j = 0; j < n; ++j) channels_.calls.at(c_.arg)(first_ + j);
        break;
      case kStop:
        // The envs end as a thread vector's do when it is destroyed (a training log records
        // their last episodes).
        envs_.clear();
        break;
      default:
        break;
    }
    export_messages();
  }

  // An env's results of this call (a reset when `stepped` is false: reward 0, flags false).
  void finish(int j, envs::StepResult r, bool stepped) {
    const int i = first_ + j;
    shm_.rewards()[i] = stepped ? r.reward : 0;
    shm_.terminated()[i] = stepped && r.terminated;
    shm_.truncated()[i] = stepped && r.truncated;
    ended_[j] = stepped && (r.terminated || r.truncated);
    export_state(j);
  }

  // Observation (the one copy), score and info values into the env's slot.
  void export_state(int j) {
    const int i = first_ + j;
    const envs::Env& env = *envs_[j];
    const envs::ObservationBuffers& from = env.observation();
    envs::ObservationBuffers& to = views_[j];
    for (int k = 0; k < from.count(); ++k) {
      const std::span<const std::byte> src = from.bytes(k);
      std::memcpy(const_cast<std::byte*>(to.bytes(k).data()), src.data(), src.size());
    }
    shm_.scores()[i] = env.score();
    const envs::Info& info = env.info();
    EnvHeader& h = shm_.header(i);
    h.steps = info.steps;
    double* numbers = shm_.numbers(i);
    Writer lists(shm_.variable(i), shm_.layout.variable_bytes, "an env's info lists");
    for (int k = 0; k < info.size(); ++k) {
      if (info.type(k) == envs::InfoType::kIntList) {
        const std::span<const int> list = info.list(k);
        lists.put<std::uint32_t>(list.size());
        lists.raw(list.data(), list.size_bytes());
      } else {
        numbers[k] = info.number(k);
      }
    }
    h.list_bytes = static_cast<std::uint32_t>(lists.size());
  }

  void export_messages() {
    if (!channels_.outbox) return;
    for (int j = 0; j < last_ - first_; ++j) {
      const int i = first_ + j;
      std::string& out = outbox_[j];
      out.clear();
      channels_.outbox(i, out);
      EnvHeader& h = shm_.header(i);
      Writer w(shm_.variable(i) + h.list_bytes, shm_.layout.variable_bytes - h.list_bytes,
               "an env's messages");
      w.raw(out.data(), out.size());
      h.message_bytes = static_cast<std::uint32_t>(out.size());
    }
  }

  ProcVecEnv::Shared& shm_;
  int w_;
  Control& c_;
  int first_, last_;
  const ProcVecEnv::Channels& channels_;
  std::vector<std::unique_ptr<envs::Env>> envs_;
  std::vector<envs::ObservationBuffers> views_;
  std::vector<std::uint8_t> ended_;
  std::vector<std::string> outbox_;
  size_t observation_bytes_ = 0;
  int action_size_ = 0;
};

}  // namespace

ProcVecEnv::ProcVecEnv(int num_envs, const EnvFactory& make, int procs, Channels channels)
    : num_envs_(num_envs), channels_(std::move(channels)) {
  if (procs < 1)
    throw UserError("a process vector needs at least 1 process, not " + std::to_string(procs));
  if (num_envs < 1 || num_envs % procs != 0) {
    throw UserError(std::to_string(num_envs) + " envs do not split evenly over " +
                    std::to_string(procs) + " processes; give a number of envs divisible by " +
                    std::to_string(procs));
  }
  envs_per_worker_ = num_envs / procs;
  shared_ = std::make_unique<Shared>(procs, num_envs);
  rewards_ = shared_->rewards();
  terminated_ = shared_->terminated();
  truncated_ = shared_->truncated();
  const pid_t parent = getpid();
  try {
    workers_.reserve(procs);
    for (int w = 0; w < procs; ++w) {
      const Worker worker{.first = w * envs_per_worker_, .last = (w + 1) * envs_per_worker_};
      // Nothing buffered is inherited, so nothing is written twice.
      std::fflush(nullptr);
      const pid_t pid = fork();
      if (pid < 0) {
        throw UserError(std::string("cannot start a worker process: ") + std::strerror(errno));
      }
      if (pid == 0) {
        // Dies with the thread that made the vector; the parent may already be gone.
        prctl(PR_SET_PDEATHSIG, SIGKILL);
        if (getppid() != parent) _exit(1);
        std::signal(SIGINT, SIG_IGN);
        std::signal(SIGTERM, SIG_IGN);
        WorkerLoop(*shared_, w, worker.first, worker.last, channels_).run(make);
      }
      workers_.push_back(worker);
      workers_.back().pid = pid;
    }
    // Every worker has built its envs and described each; every description must be env 0's.
    for (int w = 0; w < procs; ++w) wait(w);
    auto description = [&](int i) {
      std::uint64_t size = 0;
      std::memcpy(&size, shared_->slot(i), sizeof size);
      return std::string_view(reinterpret_cast<const char*>(shared_->slot(i)) + sizeof size, size);
    };
    const std::string_view first = description(0);
    for (int i = 1; i < num_envs; ++i) {
      if (description(i) != first) {
        throw std::invalid_argument("ProcVecEnv: env " + std::to_string(i) +
                                    " has spaces or info keys different from env 0's");
      }
    }
    Reader r(reinterpret_cast<const std::byte*>(first.data()), first.size());
    const Description d = parse_description(r);
    observation_space_ = d.observation_space;
    action_space_ = d.action_space;
    shared_->layout = SlotLayout(action_space_.size(), static_cast<int>(d.info.size()),
                                 envs::ObservationBuffers::bytes_needed(observation_space_));
    for (int i = 0; i < num_envs; ++i) proxies_.push_back(std::make_unique<Proxy>(*this, i, d));
  } catch (...) {
    stop_workers();
    throw;
  }
}

ProcVecEnv::~ProcVecEnv() { stop_workers(); }

void ProcVecEnv::stop_workers() {
  // A clean stop: each worker ends its envs (their messages are taken) and exits.
  if (broken_.empty()) {
    for (int w = 0; w < procs(); ++w) {
      if (workers_[w].pid > 0) post(w, kStop, 0);
    }
    for (int w = 0; w < procs(); ++w) {
      if (workers_[w].pid <= 0) continue;
      try {
        wait(w);
        import_messages(workers_[w].first, workers_[w].last);
      } catch (...) {
        // Destructors must not throw; a worker that fails here is killed below.
      }
    }
  }
  // Then every worker is reaped, after up to 2 s for it to exit, or killed.
  for (Worker& worker : workers_) {
    if (worker.pid <= 0) continue;
    int status = 0;
    for (int tries = 0; tries < 2000; ++tries) {
      if (waitpid(worker.pid, &status, WNOHANG) == worker.pid) {
        worker.pid = 0;
        break;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    if (worker.pid > 0) {
      kill(worker.pid, SIGKILL);
      while (waitpid(worker.pid, &status, 0) < 0 && errno == EINTR) {
      }
      worker.pid = 0;
    }
  }
}

std::vector<pid_t> ProcVecEnv::worker_pids() const {
  std::vector<pid_t> pids;
  for (const Worker& worker : workers_) pids.push_back(worker.pid);
  return pids;
}

void ProcVecEnv::post(int w, int command, int arg) {
  Control& c = shared_->control(w);
  c.command = command;
  c.arg = arg;
  sem_post(&c.go);
}

void ProcVecEnv::check_alive(int w) {
  Worker& worker = workers_[w];
  int status = 0;
  if (worker.pid <= 0 || waitpid(worker.pid, &status, WNOHANG) != worker.pid) return;
  const pid_t pid = std::exchange(worker.pid, 0);
  std::string how;
  if (WIFSIGNALED(status)) {
    const int sig = WTERMSIG(status);
    how = "was killed by signal " + std::to_string(sig) + " (" + strsignal(sig) + ")";
  } else {
    how = "exited with status " + std::to_string(WEXITSTATUS(status));
  }
  broken_ = "env worker " + std::to_string(w) + " (process " + std::to_string(pid) + ", envs " +
            std::to_string(worker.first) + "-" + std::to_string(worker.last - 1) + ") " + how;
  // The others are of no use without it: end them now.
  for (Worker& other : workers_) {
    if (other.pid > 0) kill(other.pid, SIGKILL);
  }
  throw UserError(broken_);
}

void ProcVecEnv::throw_if_broken() const {
  if (!broken_.empty()) throw UserError(broken_);
}

void ProcVecEnv::wait(int w) {
  Control& c = shared_->control(w);
  for (bool taken = take_soon(c.done); !taken;) {
    // Wakes every 100 ms to see whether the worker is still there.
    timespec deadline{};
    clock_gettime(CLOCK_REALTIME, &deadline);
    deadline.tv_nsec += 100'000'000;
    if (deadline.tv_nsec >= 1'000'000'000) {
      deadline.tv_nsec -= 1'000'000'000;
      ++deadline.tv_sec;
    }
    if (sem_timedwait(&c.done, &deadline) == 0) taken = true;
    if (taken) break;
    if (errno != ETIMEDOUT && errno != EINTR) {
      throw std::system_error(errno, std::generic_category(), "process vector: sem_timedwait");
    }
    check_alive(w);
  }
  switch (c.status) {
    case kOk:
      return;
    case kUserError:
      throw UserError(c.error);
    case kInvalidArgument:
      throw std::invalid_argument(c.error);
    default:
      throw std::runtime_error(c.error);
  }
}

void ProcVecEnv::run_all(int command, int arg) {
  throw_if_broken();
  for (int w = 0; w < procs(); ++w) post(w, command, arg);
  // Every worker answers before an error is thrown, so the next call starts in step.
  std::exception_ptr first;
  for (int w = 0; w < procs(); ++w) {
    try {
      wait(w);
    } catch (...) {
      if (!broken_.empty()) throw;
      if (!first) first = std::current_exception();
    }
  }
  if (command == kReset || command == kStep || command == kResetEnded) import_state();
  import_messages(0, num_envs_);
  if (first) std::rethrow_exception(first);
}

void ProcVecEnv::run_one(int w, int command, int arg) {
  throw_if_broken();
  post(w, command, arg);
  std::exception_ptr error;
  try {
    wait(w);
  } catch (...) {
    if (!broken_.empty()) throw;
    error = std::current_exception();
  }
  import_messages(workers_[w].first, workers_[w].last);
  if (error) std::rethrow_exception(error);
}

void ProcVecEnv::import_state() {
  for (int i = 0; i < num_envs_; ++i) {
    envs::Info& info = proxies_[i]->mutable_info();
    const EnvHeader& h = shared_->header(i);
    info.steps = h.steps;
    const double* numbers = shared_->numbers(i);
    Reader lists(shared_->variable(i), h.list_bytes);
    for (int k = 0; k < info.size(); ++k) {
      if (info.type(k) == envs::InfoType::kIntList) {
        std::vector<int>& list = info.list(k);
        list.resize(lists.get<std::uint32_t>());
        lists.raw(list.data(), list.size() * sizeof(int));
      } else {
        info.set(k, numbers[k]);
      }
    }
  }
}

void ProcVecEnv::import_messages(int first, int last) {
  for (int i = first; i < last; ++i) {
    EnvHeader& h = shared_->header(i);
    if (h.message_bytes == 0) continue;
    const std::string_view message(
        reinterpret_cast<const char*>(shared_->variable(i)) + h.list_bytes, h.message_bytes);
    h.message_bytes = 0;  // taken once
    if (channels_.inbox) channels_.inbox(i, message);
  }
}

void ProcVecEnv::reset(std::uint64_t seed) {
  throw_if_broken();
  for (int i = 0; i < num_envs_; ++i) shared_->seeds()[i] = ThreadedVecEnv::env_seed(seed, i);
  run_all(kReset);
  if (after_step_) after_step_();
  if (after_reset_) after_reset_();
}

void ProcVecEnv::step(std::span<const double> actions) {
  throw_if_broken();
  const size_t dim = action_space_.size();
  if (actions.size() != size() * dim) {
    throw std::invalid_argument("ProcVecEnv::step: expected " + std::to_string(size() * dim) +
                                " action values, got " + std::to_string(actions.size()));
  }
  envs::check_finite_actions(actions, static_cast<int>(dim));
  // The one copy of the actions: into each env's slot.
  for (int i = 0; i < num_envs_; ++i) {
    std::copy_n(actions.data() + i * dim, dim, shared_->actions(i));
  }
  run_all(kStep);
  if (after_step_) after_step_();
}

void ProcVecEnv::reset_ended() {
  run_all(kResetEnded);
  if (after_step_) after_step_();
}

void ProcVecEnv::call(int k) {
  if (k < 0 || k >= static_cast<int>(channels_.calls.size())) {
    throw std::invalid_argument("ProcVecEnv::call: no call " + std::to_string(k));
  }
  run_all(kCall, k);
}

const envs::ObservationBuffers& ProcVecEnv::observation(int env) const {
  return proxies_[env]->observation();
}

const envs::Info& ProcVecEnv::info(int env) const { return proxies_[env]->info(); }

envs::Env& ProcVecEnv::env(int env) { return *proxies_[env]; }

const envs::Env& ProcVecEnv::env(int env) const { return *proxies_[env]; }

}  // namespace cradle::learn

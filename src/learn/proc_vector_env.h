// ProcVecEnv: envs stepped in worker processes, so that envs which render (each with its own GL
// context) draw in parallel. Mesa keeps per-process state under every context, so the envs of a
// thread vector render one at a time under the process's GL lock; one process per core lifts it,
// as EnvPool's and Stable-Baselines3's SubprocVecEnv users do.
//
// The vector maps one shared memory block, then forks `procs` workers; worker w builds envs
// [w * M / procs, (w + 1) * M / procs) from the factory (its own GL contexts: the parent's are
// never used in a worker) and steps them in turn. Actions, seeds, observations, rewards, flags,
// scores and info values travel through the shared block (an observation is copied once, from
// the env into the block, and read there), the calls through a pair of process-shared
// semaphores per worker.
//
// Semantics are ThreadedVecEnv's: env i is seeded with ThreadedVecEnv::env_seed(seed, i) and
// autoresets on the next step, so a seed and the actions give the thread vector's trajectories
// bit for bit. env(i) is a proxy in this process: observation, info, score, layout,
// set_reset_options and close reach the env in its worker; reset and step go through the vector.
//
// Workers never outlive the vector: the destructor stops and reaps them, and a worker dies with
// the thread that made the vector (PR_SET_PDEATHSIG). They ignore SIGINT and SIGTERM, which a
// terminal or a scheduler sends to the whole process group: the run decides when to stop (after
// its checkpoint), then ends them. A worker that dies makes the next call throw a UserError
// naming it and its signal or exit status; every later call throws it again.
//
// Make the vector before the process starts threads that hold locks a worker may need (a worker
// is a copy of the thread that forked it) and from a thread that outlives it.
#pragma once

#include <sys/types.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/spaces.h"
#include "envs/env.h"
#include "learn/vec_env.h"

namespace cradle::learn {

class ProcVecEnv final : public VecEnv {
 public:
  using EnvFactory = std::function<std::unique_ptr<envs::Env>(int)>;
  // Side channels between an env's worker and this process (e.g. a training log kept here for
  // envs that record episodes there), all optional.
  struct Channels {
    // In the worker, after every call: appends what env i has for this process to `out`.
    std::function<void(int env, std::string& out)> outbox;
    // Here, in env order after every call, for each env whose outbox was not empty.
    std::function<void(int env, std::string_view message)> inbox;
    // In the worker: call(k, ...) runs calls[k] on the env ids given.
    std::vector<std::function<void(int env)>> calls;
  };

  // Forks `procs` workers for `num_envs` envs (num_envs a multiple of procs; UserError
  // otherwise) and waits until each has built its envs (a worker's failure, e.g. the factory's
  // UserError, is rethrown here with the env id). Envs must all have the same spaces.
  ProcVecEnv(int num_envs, const EnvFactory& make, int procs, Channels channels = {});
  ~ProcVecEnv() override;
  ProcVecEnv(const ProcVecEnv&) = delete;
  ProcVecEnv& operator=(const ProcVecEnv&) = delete;

  int num_envs() const override { return num_envs_; }
  int procs() const { return static_cast<int>(workers_.size()); }
  const DictSpace& observation_space() const override { return observation_space_; }
  const Box& action_space() const override { return action_space_; }
  void reset(std::uint64_t seed) override;
  void step(std::span<const double> actions) override;
  // Same-step autoreset, as ThreadedVecEnv::reset_ended.
  void reset_ended();
  // Runs channels.calls[k] on every env, each in its worker, in env order within a worker.
  void call(int k);

  const envs::ObservationBuffers& observation(int env) const override;
  std::span<const double> rewards() const override { return {rewards_, size()}; }
  std::span<const std::uint8_t> terminated() const override { return {terminated_, size()}; }
  std::span<const std::uint8_t> truncated() const override { return {truncated_, size()}; }
  const envs::Info& info(int env) const override;
  envs::Env& env(int env) override;
  const envs::Env& env(int env) const override;

  // Process ids of the live workers (0 for one already reaped), for tests and tools.
  std::vector<pid_t> worker_pids() const;

  // As ThreadedVecEnv's: called after every reset() and step() (and reset_ended()), and after
  // every reset(seed) respectively.
  void set_after_step(std::function<void()> fn) { after_step_ = std::move(fn); }
  void set_after_reset(std::function<void()> fn) { after_reset_ = std::move(fn); }

  class Proxy;
  struct Shared;

 private:
  struct Worker {
    pid_t pid = 0;
    int first = 0, last = 0;  // env ids [first, last)
  };
  size_t size() const { return static_cast<size_t>(num_envs_); }
  // Starts command `command` on every worker (or one) and waits for them.
  void run_all(int command, int arg = 0);
  void run_one(int w, int command, int arg);
  void post(int w, int command, int arg);
  void wait(int w);
  // After a state-changing call: info values from the block, then the channels' messages.
  void import_state();
  void import_messages(int first, int last);  // envs [first, last)
  // Throws the one-line error of a dead worker (reaping it), if one is dead.
  void check_alive(int w);
  void throw_if_broken() const;
  void stop_workers();
  int worker_of(int env) const { return env / envs_per_worker_; }

  int num_envs_ = 0;
  int envs_per_worker_ = 0;
  Channels channels_;
  std::unique_ptr<Shared> shared_;
  std::vector<Worker> workers_;
  DictSpace observation_space_;
  Box action_space_;
  // Views into the shared block.
  double* rewards_ = nullptr;
  std::uint8_t* terminated_ = nullptr;
  std::uint8_t* truncated_ = nullptr;
  std::vector<std::unique_ptr<Proxy>> proxies_;
  std::string broken_;  // the dead worker's error, once one died
  std::function<void()> after_step_, after_reset_;
};

}  // namespace cradle::learn

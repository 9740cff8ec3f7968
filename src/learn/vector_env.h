// ThreadedVecEnv: N envs stepped together on a thread pool, with Gymnasium 1.x next-step
// autoreset. Env i always runs on the same pool participant (i % threads; participant 0 is the
// calling thread) so its state stays in one core's cache. Vision envs each own their GL context
// and bind it per render call, so the static assignment is for locality, not correctness.
//
// Determinism: env i's seed is the i-th value derived from the vector's seed, and envs share no
// mutable state, so a seed gives bitwise-identical batches for any number of threads.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <span>
#include <thread>
#include <vector>

#include "core/thread_pool.h"
#include "learn/vec_env.h"

namespace cradle::learn {

class ThreadedVecEnv final : public VecEnv {
 public:
  // Takes ownership of the envs, which must all have the same spaces. `threads` participants
  // (<= 0: hardware concurrency; 1: run inline), never more than there are envs.
  ThreadedVecEnv(std::vector<std::unique_ptr<envs::Env>> envs, int threads);
  // Builds env i with make(i) on the participant that will step it (one env at a time), so that
  // each env's small allocations come from that thread's malloc arena, apart from other envs'.
  using EnvFactory = std::function<std::unique_ptr<envs::Env>(int)>;
  ThreadedVecEnv(int num_envs, const EnvFactory& make, int threads);

  // Seed of env i for a vector seed: the i-th derive() of Rng(seed).
  static std::uint64_t env_seed(std::uint64_t seed, int env);

  int num_envs() const override { return static_cast<int>(envs_.size()); }
  int threads() const { return pool_.size(); }
  const DictSpace& observation_space() const override { return envs_[0]->observation_space(); }
  const Box& action_space() const override { return envs_[0]->action_space(); }
  void reset(std::uint64_t seed) override;
  void step(std::span<const double> actions) override;
  // Same-step autoreset (Stable-Baselines3's convention), after step(): resets now every env
  // whose episode ended in that call, so the next step() steps it instead of resetting it. The
  // rewards and flags of that call stay as they were; observation(i) becomes the new episode's.
  void reset_ended();

  const envs::ObservationBuffers& observation(int env) const override {
    return envs_[env]->observation();
  }
  std::span<const double> rewards() const override { return rewards_; }
  std::span<const std::uint8_t> terminated() const override { return terminated_; }
  std::span<const std::uint8_t> truncated() const override { return truncated_; }
  const envs::Info& info(int env) const override { return envs_[env]->info(); }
  envs::Env& env(int env) override { return *envs_[env]; }
  const envs::Env& env(int env) const override { return *envs_[env]; }

  // Called on the calling thread after every reset() and step() (e.g. to commit a shared log in
  // env order).
  void set_after_step(std::function<void()> fn) { after_step_ = std::move(fn); }
  // Called after every reset(seed), after the after-step call (e.g. an intrinsic reward's reset).
  void set_after_reset(std::function<void()> fn) { after_reset_ = std::move(fn); }

  // Elements of one observation key per env.
  int key_size(int key_index) const;
  // Batched copy of one observation key: out holds num_envs() * key_size(key) values, env-major.
  // Any dtype converts to float32 (uint8 images as 0..255); the uint8 overload is for uint8 keys
  // only (throws std::invalid_argument otherwise).
  void gather(int key_index, std::span<float> out) const;
  void gather(int key_index, std::span<std::uint8_t> out) const;

 private:
  void start();  // checks the envs and sizes the batch buffers

  ThreadPool pool_;  // first: envs are built on it and destroyed before it
  std::vector<std::unique_ptr<envs::Env>> envs_;
  int action_size_ = 0;
  std::vector<std::uint64_t> seeds_;
  std::vector<double> rewards_;
  std::vector<std::uint8_t> terminated_, truncated_;
  std::vector<std::uint8_t> ended_;  // episode ended in the last call: reset on the next step
  std::function<void()> after_step_, after_reset_;
};

// AsyncVecEnv: N envs stepped by worker threads without a barrier, in the spirit of EnvPool's
// send/recv. send(actions, ids) queues the named envs' next steps; recv() waits for the first
// batch_size envs to finish (in the order they finished) and hands them back. Meanwhile the other
// envs keep stepping, so no step waits for the slowest env of a batch.
//
// Every env is in one of three states: held by the caller (after reset() or recv(); its
// observation, info and last results may be read, and only it may be sent), in flight (queued or
// stepping), or ready (finished, waiting for recv()). Autoreset is the lock-step vector's
// next-step autoreset: an env whose episode ended is reset by its next send (action ignored,
// reward 0, flags false, the new episode's first observation).
//
// Determinism: env i's seed is ThreadedVecEnv::env_seed(seed, i) and envs share no mutable state,
// so an env's trajectory depends only on its seed and the actions sent to it, whatever batches it
// came back in; which envs form a batch depends on timing.
//
// The VecEnv face is lock-step on top: reset() leaves every env held; step() sends every env and
// waits for all (every env must be held). Learners that know the async face (RolloutCollector)
// use send/recv instead.
class AsyncVecEnv final : public VecEnv {
 public:
  // Takes ownership of the envs (same spaces). 1 <= batch_size <= envs; `threads` workers
  // (<= 0: hardware concurrency), never more than there are envs. UserError otherwise.
  AsyncVecEnv(std::vector<std::unique_ptr<envs::Env>> envs, int batch_size, int threads);
  ~AsyncVecEnv() override;
  AsyncVecEnv(const AsyncVecEnv&) = delete;
  AsyncVecEnv& operator=(const AsyncVecEnv&) = delete;

  // What recv() returns: slot j is env ids[j]. Spans into the vector's buffers, valid until the
  // next recv(), step() or reset().
  struct Batch {
    std::span<const int> ids;
    std::span<const double> rewards;
    std::span<const std::uint8_t> terminated, truncated;
    int size() const { return static_cast<int>(ids.size()); }
  };
  // Queues the next step of envs `ids` (each held, no repeats); actions: ids.size() x action
  // dim, row-major. UserError on a wrong id or size.
  void send(std::span<const double> actions, std::span<const int> ids);
  // Waits for batch_size envs to be ready (or for every env in flight, when fewer are) and holds
  // them. UserError when no env is in flight or ready.
  Batch recv();

  int num_envs() const override { return static_cast<int>(envs_.size()); }
  int batch_size() const { return batch_size_; }
  int threads() const { return static_cast<int>(workers_.size()); }
  // Envs held by the caller.
  int held() const { return held_count_; }
  const DictSpace& observation_space() const override { return envs_[0]->observation_space(); }
  const Box& action_space() const override { return envs_[0]->action_space(); }
  // Waits for the envs in flight, then resets every env (env i with env_seed(seed, i)); all held.
  void reset(std::uint64_t seed) override;
  // Lock-step: every env must be held (UserError otherwise); sends all and waits for all.
  void step(std::span<const double> actions) override;

  // Of a held env: its observation, info and last results (by env id).
  const envs::ObservationBuffers& observation(int env) const override {
    return envs_[env]->observation();
  }
  std::span<const double> rewards() const override { return rewards_; }
  std::span<const std::uint8_t> terminated() const override { return terminated_; }
  std::span<const std::uint8_t> truncated() const override { return truncated_; }
  const envs::Info& info(int env) const override { return envs_[env]->info(); }
  envs::Env& env(int env) override { return *envs_[env]; }
  const envs::Env& env(int env) const override { return *envs_[env]; }

  // Called on the calling thread after every recv(), reset() and step() (e.g. to commit a shared
  // log in env order), as ThreadedVecEnv's.
  void set_after_step(std::function<void()> fn) { after_step_ = std::move(fn); }
  // Called after every reset(seed), after the after-step call (e.g. an intrinsic reward's reset).
  void set_after_reset(std::function<void()> fn) { after_reset_ = std::move(fn); }

 private:
  enum class Job : std::uint8_t { kStep, kReset };
  // Queues held env ids (the caller's thread).
  void enqueue(std::span<const int> ids);
  // Waits until `want` envs are ready and moves the first `want` of them into ids_ (held).
  void take(int want);
  void worker_loop();
  // Runs env e's queued job (a worker thread).
  void run(int e);
  void stop_workers();

  std::vector<std::unique_ptr<envs::Env>> envs_;
  int batch_size_ = 0;
  int action_size_ = 0;
  // Per env: the caller writes these while the env is held, the worker that runs it while it is
  // in flight; the queues' mutex orders the two.
  std::vector<double> actions_;  // envs x action dim
  std::vector<Job> jobs_;
  std::vector<std::uint64_t> seeds_;
  std::vector<double> rewards_;
  std::vector<std::uint8_t> terminated_, truncated_;
  std::vector<std::uint8_t> ended_;  // episode ended in the last step: the next send resets it
  std::vector<std::exception_ptr> errors_;
  // The caller's side: which envs it holds, the last batch, and send's check marks.
  std::vector<std::uint8_t> held_, marked_;
  int held_count_ = 0;
  std::vector<int> ids_, all_ids_;
  std::vector<double> batch_rewards_;
  std::vector<std::uint8_t> batch_terminated_, batch_truncated_;
  // Two FIFO rings of env ids (capacity envs each), guarded by mutex_: queued jobs and finished
  // envs. The sizes are atomics too, so that waiters poll them before sleeping.
  std::mutex mutex_;
  std::condition_variable work_cv_, ready_cv_;
  std::vector<int> queue_, ready_;
  int queue_head_ = 0, ready_head_ = 0;
  std::atomic<int> queued_{0}, finished_{0};
  int sleeping_workers_ = 0;
  int caller_wants_ = 0;  // > 0 while the caller sleeps for that many ready envs
  bool stop_ = false;
  std::function<void()> after_step_, after_reset_;
  std::vector<std::thread> workers_;
};

// Sets the after-reset call of a ThreadedVecEnv, an AsyncVecEnv or a ProcVecEnv
// (std::invalid_argument for another VecEnv).
void set_after_reset(VecEnv& vec, std::function<void()> fn);

// The batch of an AsyncVecEnv as a VecEnv of batch.size() envs: env j is the batch's env ids[j]
// (its observation, info, and the batch's rewards and flags; env_id(j) = ids[j]). For code written
// against VecEnv (observation pipelines, reward hooks) on a batch; reset() and step() throw
// std::logic_error.
class BatchView final : public VecEnv {
 public:
  BatchView(AsyncVecEnv& vec, const AsyncVecEnv::Batch& batch) : vec_(vec), batch_(batch) {}
  int num_envs() const override { return batch_.size(); }
  const DictSpace& observation_space() const override { return vec_.observation_space(); }
  const Box& action_space() const override { return vec_.action_space(); }
  void reset(std::uint64_t seed) override;
  void step(std::span<const double> actions) override;
  const envs::ObservationBuffers& observation(int env) const override {
    return vec_.observation(batch_.ids[env]);
  }
  std::span<const double> rewards() const override { return batch_.rewards; }
  std::span<const std::uint8_t> terminated() const override { return batch_.terminated; }
  std::span<const std::uint8_t> truncated() const override { return batch_.truncated; }
  const envs::Info& info(int env) const override { return vec_.info(batch_.ids[env]); }
  envs::Env& env(int env) override { return vec_.env(batch_.ids[env]); }
  const envs::Env& env(int env) const override { return vec_.env(batch_.ids[env]); }
  int env_id(int slot) const override { return batch_.ids[slot]; }

 private:
  AsyncVecEnv& vec_;
  AsyncVecEnv::Batch batch_;
};

}  // namespace cradle::learn

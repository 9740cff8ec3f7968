// ThreadedVecEnv: N envs stepped together on a thread pool, with Gymnasium 1.x next-step
// autoreset. Env i always runs on the same pool participant (i % threads; participant 0 is the
// calling thread) so its state stays in one core's cache. Vision envs each own their GL context
// and bind it per render call, so the static assignment is for locality, not correctness.
//
// Determinism: env i's seed is the i-th value derived from the vector's seed, and envs share no
// mutable state, so a seed gives bitwise-identical batches for any number of threads.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "core/config.h"
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

}  // namespace cradle::learn

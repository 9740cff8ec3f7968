// Vectorized environments: N envs stepped together (on a thread pool), with Gymnasium 1.x
// next-step autoreset. Learners see only this interface: spaces, per-env observation buffers,
// batched rewards and episode flags.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "core/spaces.h"
#include "envs/env.h"

namespace cradle::learn {

class VecEnv {
 public:
  virtual ~VecEnv() = default;
  virtual int num_envs() const = 0;
  // Spaces of one env (every env of a vector has the same).
  virtual const DictSpace& observation_space() const = 0;
  virtual const Box& action_space() const = 0;
  // Resets every env; env i gets its own seed derived from `seed`.
  virtual void reset(std::uint64_t seed) = 0;
  // actions: num_envs x action dim, row-major. Next-step autoreset: an env whose episode ended in
  // the previous call is reset by this call instead of stepped; for it this call reports
  // reward 0, terminated and truncated false, and its observation is the new episode's first.
  virtual void step(std::span<const double> actions) = 0;

  virtual const envs::ObservationBuffers& observation(int env) const = 0;
  virtual std::span<const double> rewards() const = 0;
  virtual std::span<const std::uint8_t> terminated() const = 0;
  virtual std::span<const std::uint8_t> truncated() const = 0;
  // Info of env i after the last call (for an autoreset env: the new episode's).
  virtual const envs::Info& info(int env) const = 0;
  virtual envs::Env& env(int env) = 0;
  virtual const envs::Env& env(int env) const = 0;
  // The id of env `slot` in the underlying vector: the slot itself, except for views of part of
  // a vector (BatchView). Per-env state kept across calls (intrinsic rewards) is indexed by it.
  virtual int env_id(int slot) const { return slot; }
};

}  // namespace cradle::learn

// A task measures (and may reward) what the body does; it never changes the physics
// (dm_control's split). BabyBench behaviours return reward 0 and fill the info.
#pragma once

#include <mujoco/mujoco.h>

#include <memory>

#include "core/config.h"
#include "envs/env.h"

namespace cradle::envs {

class Task {
 public:
  virtual ~Task() = default;
  // Once, when the env is built: the info keys the task writes.
  virtual void declare(Info& info) { (void)info; }
  // At the start of an episode, after the start state is set.
  virtual void reset(const mjModel* m, const mjData* d, Info& info) = 0;
  // After each env step's physics; returns the reward.
  virtual double after_step(const mjModel* m, const mjData* d, Info& info) = 0;
  // Score of an episode of `steps` env steps from its info (NaN: the task measures nothing).
  virtual double score(const Info& info, int steps) const;
};

// The BabyBench behaviour named by the config ("none" measures nothing).
std::unique_ptr<Task> make_behaviour(const Config& config, const mjModel* m);

}  // namespace cradle::envs

// Walker (tma_sami.md §7.1, sami_models.md §1.4): gym's Walker2d, its mass and damping scaled.
// Reward: the forward velocity plus 1 minus 1e-3 ||a||^2; no termination (SaMI's runs go on to
// the horizon).
#include <algorithm>
#include <string>
#include <vector>

#include "sami/envs/env_def.h"

namespace cradle::sami::envs {
namespace {

std::string robot_model() { return planar_robot(true); }

// The forward velocity plus 1 (alive) minus the control cost.
double reward(const LocomotionStep& s) { return s.velocity + 1.0 - s.ctrl; }

// qpos but root x, qvel clipped to [-10, 10].
void observe(const mjModel* m, const mjData* d, double /*velocity*/, double* o) {
  o = std::copy_n(d->qpos + 1, m->nq - 1, o);
  for (int i = 0; i < m->nv; ++i) *o++ = std::clamp(d->qvel[i], -10.0, 10.0);
}

// Hopper's sets (SaMI's tools/rewrite_config.py has none of its own for the Walker); the extreme
// ones equal the moderate ones.
std::vector<TaskSet> split_sets(Split split) {
  if (split == Split::kTrain) return quadrants({0.5, 0.75}, {1.0, 1.25, 1.5});
  return quadrants({0.25, 0.375}, {1.75, 2.0});
}

}  // namespace

const EnvDef& walker() {
  static const EnvDef def = {
      .name = "Walker",
      .robot = Robot::kWalker,
      .model = robot_model,
      .obs_size = 17,
      .action_size = 6,
      .horizon = 2000,
      .frame_skip = 4,
      .dt = 0.008,
      .varies = {.mass = true, .damping = true},
      .split_sets = split_sets,
      .locomotion = {.reward = reward,
                     .observe = observe,
                     .scale = scale_mass_and_damping,
                     .ctrl_cost = 1e-3,
                     .ctrl_cost_f32 = true,
                     .uniform_pos = true,
                     .uniform_vel = true,
                     .pos_noise = 0.005,
                     .vel_noise = 0.005},
  };
  return def;
}

}  // namespace cradle::sami::envs

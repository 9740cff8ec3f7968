// HumanoidStandup (tma_sami.md §7.1): SlimHumanoid's humanoid, spec (with a horizon of 2,000
// steps), observation, sets and noise with gym's HumanoidStandup reward: the torso's height per
// timestep minus 0.1 ||a||^2 and the impact cost, plus 1.
#include <algorithm>

#include "sami/envs/env_def.h"

namespace cradle::sami::envs {
namespace {

// The impact cost reads cfrc_ext, zero unless Options::contact_forces (as in the published runs).
double reward(const LocomotionStep& s) {
  return s.data->qpos[2] / s.model->opt.timestep - s.ctrl -
         std::min(0.5e-6 * s.cfrc_squares(false), 10.0) + 1.0;
}

}  // namespace

const EnvDef& humanoid_standup() {
  static const EnvDef def = [] {
    EnvDef d = slim_humanoid();
    d.name = "HumanoidStandup";
    d.horizon = 2000;
    d.locomotion.reward = reward;
    d.locomotion.info_start_vx = false;
    return d;
  }();
  return def;
}

}  // namespace cradle::sami::envs

// CrippleHopper (tma_sami.md §7.1): Hopper (its model, reward and observation) with 1e-3
// ||a||^2 as its control cost, a horizon of 1,000 steps, only the mass varied and, in the
// extreme test only, one of its three joints crippled (actuator masked, geom red).
#include <vector>

#include "sami/envs/env_def.h"

namespace cradle::sami::envs {
namespace {

// Joint j (thigh, leg, foot): actuator j, geom j + 2 (after the floor and the torso).
CrippleParts cripple(int joint) { return {.actuators = {joint, -1}, .geoms = {joint + 2, -1}}; }

std::vector<TaskSet> split_sets(Split split) {
  if (split == Split::kTrain) return mass_groups({kTrainMass}, {});
  if (split == Split::kModerate) return mass_groups(kModerateMass, {});
  return mass_groups(kExtremeMass, singles({0, 1, 2}));
}

}  // namespace

const EnvDef& cripple_hopper() {
  static const EnvDef def = [] {
    EnvDef d = hopper();
    d.name = "CrippleHopper";
    d.horizon = 1000;
    d.varies = {.mass = true, .cripple_units = 3, .max_crippled = 2};
    d.split_sets = split_sets;
    d.locomotion.scale = scale_mass;
    d.locomotion.cripple = cripple;
    // The planar envs' weight (the Walker's), not the Hopper's 0.1, summed in float64 (the mask
    // multiplies the action in float64).
    d.locomotion.ctrl_cost = 1e-3;
    d.locomotion.ctrl_cost_f32 = false;
    return d;
  }();
  return def;
}

}  // namespace cradle::sami::envs

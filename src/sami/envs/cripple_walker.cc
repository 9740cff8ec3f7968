// CrippleWalker (tma_sami.md §7.1): Walker (its model, spec, reward and observation) with one
// joint of a leg crippled per episode (two in the extreme test: one of each leg; actuator masked,
// geom red) and only the mass varied.
#include <vector>

#include "sami/envs/env_def.h"

namespace cradle::sami::envs {
namespace {

// Joint j (right thigh, leg, foot, then the left ones): actuator j, geom j + 2 (after the floor
// and the torso).
CrippleParts cripple(int joint) { return {.actuators = {joint, -1}, .geoms = {joint + 2, -1}}; }

std::vector<TaskSet> split_sets(Split split) {
  if (split == Split::kTrain) return mass_groups({kTrainMass}, singles({0, 1, 2}));
  if (split == Split::kModerate) return mass_groups(kModerateMass, singles({3, 4, 5}));
  return mass_groups(kExtremeMass, pairs({0, 1, 2}, {3, 4, 5}));
}

}  // namespace

const EnvDef& cripple_walker() {
  static const EnvDef def = [] {
    EnvDef d = walker();
    d.name = "CrippleWalker";
    d.varies = {.mass = true, .cripple_units = 6, .max_crippled = 2};
    d.split_sets = split_sets;
    d.locomotion.scale = scale_mass;
    d.locomotion.cripple = cripple;
    // The mask multiplies the action in float64, so ||a||^2 is a float64 sum.
    d.locomotion.ctrl_cost_f32 = false;
    return d;
  }();
  return def;
}

}  // namespace cradle::sami::envs

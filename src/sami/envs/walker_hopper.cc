// WalkerHopper (tma_sami.md §7.1): Walker (its model, spec, reward and observation) made a hopper
// by disabling a whole leg as SaMI's mode [3] does it (geometry only: red, half radius and half
// length, no mask), only the mass varied; the moderate test cripples single joints (masked).
#include <vector>

#include "sami/envs/env_def.h"

namespace cradle::sami::envs {
namespace {

// Joint j (right thigh, leg, foot, then the left ones): actuator j, geom j + 2 (after the floor
// and the torso).
CrippleParts cripple(int joint) { return {.actuators = {joint, -1}, .geoms = {joint + 2, -1}}; }

std::vector<TaskSet> split_sets(Split split) {
  // The whole right leg "disabled" as SaMI's mode [3] does it (geometry only, no mask).
  if (split == Split::kTrain) return mass_groups({kTrainMass}, {{0, 1, 2}}, false);
  if (split == Split::kModerate) return mass_groups(kModerateMass, singles({0, 1, 2}));
  std::vector<TaskSet> sets = mass_groups(kExtremeMass, {{3, 4, 5}}, false);
  for (TaskSet& t : mass_groups(kExtremeMass, singles({3, 4, 5}))) sets.push_back(t);
  return sets;
}

}  // namespace

const EnvDef& walker_hopper() {
  static const EnvDef def = [] {
    EnvDef d = walker();
    d.name = "WalkerHopper";
    d.varies = {.mass = true, .cripple_units = 6, .max_crippled = 3};
    d.split_sets = split_sets;
    d.locomotion.scale = scale_mass;
    d.locomotion.cripple = cripple;
    d.locomotion.shrink = true;
    // The mask multiplies the action in float64, so ||a||^2 is a float64 sum.
    d.locomotion.ctrl_cost_f32 = false;
    return d;
  }();
  return def;
}

}  // namespace cradle::sami::envs

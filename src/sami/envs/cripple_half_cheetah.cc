// CrippleHalfCheetah (tma_sami.md §7.1): HalfCheetah (its model, spec, reward and observation)
// with one or two of its six joints crippled per episode (the actuator masked, the geom red) and
// only the mass varied.
#include <vector>

#include "sami/envs/env_def.h"

namespace cradle::sami::envs {
namespace {

// Joint j (bthigh, bshin, bfoot, fthigh, fshin, ffoot): actuator j, geom j + 3 (after the floor,
// the torso and the head).
CrippleParts cripple(int joint) { return {.actuators = {joint, -1}, .geoms = {joint + 3, -1}}; }

// The README's qualitative cripple splits: a front joint in training, a back one in the moderate
// test.
std::vector<TaskSet> split_sets(Split split) {
  if (split == Split::kTrain) return mass_groups({kTrainMass}, singles({3, 4, 5}));
  if (split == Split::kModerate) return mass_groups(kModerateMass, singles({0, 1, 2}));
  // Two distinct joints of all six: the env's two-joint mode draws both from one set (it cannot
  // ask for one front and one back), and SaMI's own extreme demo cripples 4 and 5.
  const std::vector<int> all = {0, 1, 2, 3, 4, 5};
  return mass_groups(kExtremeMass, pairs(all, all));
}

}  // namespace

const EnvDef& cripple_half_cheetah() {
  static const EnvDef def = [] {
    EnvDef d = half_cheetah();
    d.name = "CrippleHalfCheetah";
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

// CrippleAnt (tma_sami.md §7.1): Ant (its model, reward and forward term) with one or two legs
// crippled per episode (both actuators masked, thigh and lower leg red and shrunk to half radius
// and half length), only the mass varied, and an observation of its own (41 values).
#include <algorithm>
#include <vector>

#include "sami/envs/env_def.h"

namespace cradle::sami::envs {
namespace {

// Leg k (0-based, SaMI's numbering): its two actuators, its thigh and lower-leg geoms.
constexpr int kLegActuators[4][2] = {{2, 3}, {4, 5}, {6, 7}, {0, 1}};
CrippleParts cripple(int leg) {
  return {.actuators = {kLegActuators[leg][0], kLegActuators[leg][1]},
          .geoms = {3 + 3 * leg, 4 + 3 * leg}};
}

// qpos, qvel, the torso's orientation and position.
void observe(const mjModel* m, const mjData* d, double /*velocity*/, double* o) {
  o = std::copy_n(d->qpos, m->nq, o);
  o = std::copy_n(d->qvel, m->nv, o);
  o = std::copy_n(d->xmat + 9, 9, o);
  std::copy_n(d->xpos + 3, 3, o);
}

std::vector<TaskSet> split_sets(Split split) {
  if (split == Split::kTrain) return mass_groups({kTrainMass}, singles({0, 1, 2, 3}));
  if (split == Split::kModerate) return mass_groups(kModerateMass, singles({0, 1, 2, 3}));
  return mass_groups(kExtremeMass, pairs({0, 1, 2, 3}, {0, 1, 2, 3}));
}

}  // namespace

const EnvDef& cripple_ant() {
  static const EnvDef def = [] {
    EnvDef d = ant();
    d.name = "CrippleAnt";
    d.obs_size = 41;
    d.varies = {.mass = true, .cripple_units = 4, .max_crippled = 2};
    d.split_sets = split_sets;
    d.locomotion.observe = observe;
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

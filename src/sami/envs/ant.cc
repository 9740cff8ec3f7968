// Ant (tma_sami.md §7.1, sami_models.md §1.1): gym's Ant; the mass and damping factor scale one
// half of the legs and their reciprocal the other. Reward: the torso's forward velocity minus
// 0.01 ||a||^2 and the contact cost, plus 1.
#include <algorithm>
#include <string>
#include <vector>

#include "sami/envs/env_def.h"

namespace cradle::sami::envs {
namespace {

// Ant (§1.1): a sphere torso and four legs along the diagonals d_k, density 5, degrees.
std::string robot_model() {
  XmlWriter x;
  x.open("mujoco", {{"model", "ant"}});
  x.leaf("compiler", {{"angle", "degree"}, {"coordinate", "local"}, {"inertiafromgeom", "true"}});
  x.leaf("option", {{"integrator", "RK4"}, {"timestep", "0.01"}});
  x.open("default");
  x.leaf("joint", {{"armature", "1"}, {"damping", "1"}, {"limited", "true"}});
  x.leaf("geom", {{"conaffinity", "0"},
                  {"condim", "3"},
                  {"density", "5"},
                  {"friction", "1 .5 .5"},
                  {"margin", ".01"},
                  {"rgba", ".8 .6 .4 1"}});
  x.close();
  scenery(x);
  x.open("worldbody");
  light(x);
  x.leaf("geom", {{"name", "floor"},
                  {"type", "plane"},
                  {"size", "40 40 40"},
                  {"conaffinity", "1"},
                  {"condim", "3"},
                  {"material", "grid"}});
  x.open("body", {{"name", "torso"}, {"pos", "0 0 .75"}});
  track_camera(x, 3.5, 2, true);
  x.leaf("geom", {{"name", "torso_geom"}, {"type", "sphere"}, {"pos", "0 0 0"}, {"size", ".25"}});
  x.leaf("joint", {{"name", "root"},
                   {"type", "free"},
                   {"armature", "0"},
                   {"damping", "0"},
                   {"limited", "false"},
                   {"margin", ".01"}});
  const char* roots[4] = {"front_left_leg", "front_right_leg", "back_leg", "right_back_leg"};
  const double dirs[4][2] = {{1, 1}, {-1, 1}, {-1, -1}, {1, -1}};
  const char* ankle_axis[4] = {"-1 1 0", "1 1 0", "-1 1 0", "1 1 0"};
  const char* ankle_range[4] = {"30 70", "-70 -30", "-70 -30", "30 70"};
  for (int k = 0; k < 4; ++k) {
    const std::string n = std::to_string(k + 1);
    const double dx = dirs[k][0], dy = dirs[k][1];
    auto seg = [&](double len) { return nums({0, 0, 0, len * dx, len * dy, 0}); };
    x.open("body", {{"name", roots[k]}, {"pos", "0 0 0"}});
    x.leaf("geom", {{"name", "aux_" + n + "_geom"},
                    {"type", "capsule"},
                    {"fromto", seg(0.2)},
                    {"size", ".08"}});
    x.open("body", {{"name", "aux_" + n}, {"pos", nums({0.2 * dx, 0.2 * dy, 0})}});
    x.leaf("joint", {{"name", "hip_" + n},
                     {"type", "hinge"},
                     {"pos", "0 0 0"},
                     {"axis", "0 0 1"},
                     {"range", "-30 30"}});
    x.leaf("geom", {{"name", "leg_" + n + "_geom"},
                    {"type", "capsule"},
                    {"fromto", seg(0.2)},
                    {"size", ".08"}});
    x.open("body", {{"pos", nums({0.2 * dx, 0.2 * dy, 0})}});
    x.leaf("joint", {{"name", "ankle_" + n},
                     {"type", "hinge"},
                     {"pos", "0 0 0"},
                     {"axis", ankle_axis[k]},
                     {"range", ankle_range[k]}});
    x.leaf("geom", {{"name", "ankle_" + n + "_geom"},
                    {"type", "capsule"},
                    {"fromto", seg(0.4)},
                    {"size", ".08"}});
    x.close().close().close();
  }
  x.close().close();
  x.open("actuator");
  for (int k : {4, 1, 2, 3}) {
    for (const char* j : {"hip_", "ankle_"}) {
      const std::string joint = j + std::to_string(k);
      x.leaf("motor", {{"name", joint},
                       {"joint", joint},
                       {"gear", "150"},
                       {"ctrllimited", "true"},
                       {"ctrlrange", "-1 1"}});
    }
  }
  x.close().close();
  return x.str();
}

// The contact cost reads cfrc_ext, zero unless Options::contact_forces (as in the published
// runs).
double reward(const LocomotionStep& s) {
  return s.velocity - s.ctrl - 0.5 * s.cfrc_squares(true) + 1.0;
}

// The torso's forward velocity, qpos but root x and y, qvel.
void observe(const mjModel* m, const mjData* d, double velocity, double* o) {
  *o++ = velocity;
  o = std::copy_n(d->qpos + 2, m->nq - 2, o);
  std::copy_n(d->qvel, m->nv, o);
}

// Bodies and dofs 2..7 times the factor, 8..13 times its reciprocal (the reference multiplies by
// 1.0 / factor, which differs from dividing by one ulp for some factors): for bodies that is legs
// 1-2 against 3-4, for dofs (which start with 6 root dofs) leg 1 against legs 2-4.
void scale(const mjModel* shared, mjModel* own, double mass, double damping) {
  const double inv_mass = 1.0 / mass, inv_damping = 1.0 / damping;
  for (int i = 2; i < 14; ++i) {
    own->body_mass[i] = shared->body_mass[i] * (i < 8 ? mass : inv_mass);
    own->dof_damping[i] = shared->dof_damping[i] * (i < 8 ? damping : inv_damping);
  }
}

std::vector<TaskSet> split_sets(Split split) {
  // The extreme test of SaMI's tools/rewrite_config.py: m in 0.40..0.60 by 0.05, d = 1.
  if (split == Split::kExtreme) return {{.mass = {0.4, 0.45, 0.5, 0.55, 0.6}, .damping = {1.0}}};
  const int s = static_cast<int>(split);
  const Values lo[2] = {{0.75, 0.85}, {0.4, 0.5}};
  const Values hi[2] = {{1.0, 1.15, 1.25}, {1.5, 1.6}};
  return quadrants(lo[s], hi[s]);
}

}  // namespace

const EnvDef& ant() {
  static const EnvDef def = {
      .name = "Ant",
      .robot = Robot::kAnt,
      .model = robot_model,
      .obs_size = 28,
      .action_size = 8,
      .horizon = 2000,
      .frame_skip = 5,
      .dt = 0.05,
      .varies = {.mass = true, .damping = true},
      .split_sets = split_sets,
      .locomotion = {.reward = reward,
                     .observe = observe,
                     .scale = scale,
                     .forward = Forward::kTorsoXpos,
                     .ctrl_cost = 0.01,
                     .ctrl_cost_f32 = true,
                     .uniform_pos = true,
                     .pos_noise = 0.1,
                     .vel_noise = 0.1},
  };
  return def;
}

}  // namespace cradle::sami::envs

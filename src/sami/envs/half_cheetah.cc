// HalfCheetah (tma_sami.md §7.1, sami_models.md §1.2): gym's Half-Cheetah, its mass and damping
// scaled by factors of the DOMINO/CaDM settings. Reward: the forward velocity minus 0.1 ||a||^2.
#include <algorithm>
#include <string>
#include <vector>

#include "sami/envs/env_def.h"

namespace cradle::sami::envs {
namespace {

// Half-Cheetah (sami_models.md §1.2): capsules r 0.046 given as pos, half-length and a rotation
// about y; settotalmass 14 rescales the density-1000 masses.
std::string robot_model() {
  XmlWriter x;
  x.open("mujoco", {{"model", "half_cheetah"}});
  x.leaf("compiler", {{"angle", "radian"},
                      {"coordinate", "local"},
                      {"inertiafromgeom", "true"},
                      {"settotalmass", "14"}});
  x.open("default");
  x.leaf("joint", {{"armature", ".1"},
                   {"damping", ".01"},
                   {"limited", "true"},
                   {"solimplimit", "0 .8 .03"},
                   {"solreflimit", ".02 1"},
                   {"stiffness", "8"}});
  x.leaf("geom", {{"conaffinity", "0"},
                  {"condim", "3"},
                  {"contype", "1"},
                  {"friction", ".4 .1 .1"},
                  {"rgba", ".8 .6 .4 1"},
                  {"solimp", "0 .8 .01"},
                  {"solref", ".02 1"}});
  x.leaf("motor", {{"ctrllimited", "true"}, {"ctrlrange", "-1 1"}});
  x.close();
  x.leaf("option", {{"gravity", "0 0 -9.81"}, {"timestep", "0.01"}});
  scenery(x);
  x.open("worldbody");
  light(x);
  x.leaf("geom", {{"name", "floor"},
                  {"type", "plane"},
                  {"size", "200 200 .5"},
                  {"conaffinity", "1"},
                  {"condim", "3"},
                  {"material", "grid"}});
  x.open("body", {{"name", "torso"}, {"pos", "0 0 .7"}});
  track_camera(x, 3, 0);
  const Attrs root = {
      {"armature", "0"}, {"damping", "0"}, {"limited", "false"}, {"stiffness", "0"}};
  auto root_joint = [&](const char* name, const char* type, const char* axis) {
    Attrs a = {{"name", name}, {"type", type}, {"axis", axis}, {"pos", "0 0 0"}};
    a.insert(a.end(), root.begin(), root.end());
    x.leaf("joint", a);
  };
  root_joint("rootx", "slide", "1 0 0");
  root_joint("rootz", "slide", "0 0 1");
  root_joint("rooty", "hinge", "0 1 0");
  x.leaf("geom",
         {{"name", "torso"}, {"type", "capsule"}, {"fromto", "-.5 0 0 .5 0 0"}, {"size", ".046"}});
  x.leaf("geom", {{"name", "head"},
                  {"type", "capsule"},
                  {"pos", ".6 0 .1"},
                  {"axisangle", "0 1 0 .87"},
                  {"size", ".046 .15"}});
  // One leg segment: body, hinge about +y at its origin, capsule.
  struct Part {
    const char *name, *pos, *range, *stiffness, *damping, *geom_pos, *angle, *half;
  };
  auto part = [&](const Part& p) {
    x.open("body", {{"name", p.name}, {"pos", p.pos}});
    x.leaf("joint", {{"name", p.name},
                     {"type", "hinge"},
                     {"axis", "0 1 0"},
                     {"pos", "0 0 0"},
                     {"range", p.range},
                     {"stiffness", p.stiffness},
                     {"damping", p.damping}});
    x.leaf("geom", {{"name", p.name},
                    {"type", "capsule"},
                    {"pos", p.geom_pos},
                    {"axisangle", std::string("0 1 0 ") + p.angle},
                    {"size", std::string(".046 ") + p.half}});
  };
  part({"bthigh", "-.5 0 0", "-.52 1.05", "240", "6", ".1 0 -.13", "-3.8", ".145"});
  part({"bshin", ".16 0 -.25", "-.785 .785", "180", "4.5", "-.14 0 -.07", "-2.03", ".15"});
  part({"bfoot", "-.28 0 -.14", "-.4 .785", "120", "3", ".03 0 -.097", "-.27", ".094"});
  x.close().close().close();
  part({"fthigh", ".5 0 0", "-1 .7", "180", "4.5", "-.07 0 -.12", ".52", ".133"});
  part({"fshin", "-.14 0 -.24", "-1.2 .87", "120", "3", ".065 0 -.09", "-.6", ".106"});
  part({"ffoot", ".13 0 -.18", "-.5 .5", "60", "1.5", ".045 0 -.07", "-.6", ".07"});
  x.close().close().close();
  x.close().close();
  gear_motors(x, {{"bthigh", "120"},
                  {"bshin", "90"},
                  {"bfoot", "60"},
                  {"fthigh", "120"},
                  {"fshin", "60"},
                  {"ffoot", "30"}});
  x.close();
  return x.str();
}

// The forward velocity (the float32 observation's first entry) minus the control cost.
double reward(const LocomotionStep& s) {
  return static_cast<double>(static_cast<float>(s.velocity)) - s.ctrl;
}

// The forward velocity, qpos but root x, qvel.
void observe(const mjModel* m, const mjData* d, double velocity, double* o) {
  *o++ = velocity;
  o = std::copy_n(d->qpos + 1, m->nq - 1, o);
  std::copy_n(d->qvel, m->nv, o);
}

// Mass x damping quadrants of the DOMINO/CaDM settings (§7.1 table (b)).
std::vector<TaskSet> split_sets(Split split) {
  const int s = static_cast<int>(split);
  const Values lo[3] = {{0.75, 0.85}, {0.4, 0.5}, {0.2, 0.3}};
  const Values hi[3] = {{1.0, 1.15, 1.25}, {1.5, 1.6}, {1.7, 1.8}};
  return quadrants(lo[s], hi[s]);
}

}  // namespace

const EnvDef& half_cheetah() {
  static const EnvDef def = {
      .name = "HalfCheetah",
      .robot = Robot::kHalfCheetah,
      .model = robot_model,
      .obs_size = 18,
      .action_size = 6,
      .horizon = 1000,
      .frame_skip = 5,
      .dt = 0.05,
      .varies = {.mass = true, .damping = true},
      .split_sets = split_sets,
      .locomotion = {.reward = reward,
                     .observe = observe,
                     .scale = scale_mass_and_damping,
                     .ctrl_cost = 0.1,
                     .ctrl_cost_f32 = true,
                     .pos_noise = 0.001,
                     .vel_noise = 0.001},
  };
  return def;
}

}  // namespace cradle::sami::envs

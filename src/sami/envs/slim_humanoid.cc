// SlimHumanoid (tma_sami.md §7.1, sami_models.md §1.5): the lying humanoid of
// humanoidstandup.xml with gym's humanoid reward, its mass and damping scaled. Reward: 0.25 / dt
// per m/s of the start's root x-velocity minus 0.1 ||a||^2 plus 5 while the torso is between 1
// and 2 m high; no termination.
#include <algorithm>
#include <string>
#include <vector>

#include "sami/envs/env_def.h"

namespace cradle::sami::envs {
namespace {

// The lying humanoid of humanoidstandup.xml (§1.5), used by SlimHumanoid and HumanoidStandup.
// The two fixed tendons have no dynamic effect and are left out.
std::string robot_model() {
  XmlWriter x;
  x.open("mujoco", {{"model", "humanoidstandup"}});
  x.leaf("compiler", {{"angle", "degree"}, {"coordinate", "local"}, {"inertiafromgeom", "true"}});
  x.open("default");
  x.leaf("joint", {{"armature", "1"}, {"damping", "1"}, {"limited", "true"}});
  x.leaf("geom", {{"conaffinity", "1"},
                  {"condim", "1"},
                  {"contype", "1"},
                  {"margin", "0.001"},
                  {"rgba", ".8 .6 .4 1"}});
  x.leaf("motor", {{"ctrllimited", "true"}, {"ctrlrange", "-.4 .4"}});
  x.close();
  x.leaf("option",
         {{"integrator", "RK4"}, {"timestep", "0.003"}, {"solver", "PGS"}, {"iterations", "50"}});
  scenery(x);
  x.open("worldbody");
  light(x);
  x.leaf("geom", {{"name", "floor"},
                  {"type", "plane"},
                  {"size", "20 20 .125"},
                  {"condim", "3"},
                  {"friction", "1 .1 .1"},
                  {"material", "grid"}});
  auto capsule = [&](const char* name, const char* fromto, const char* r) {
    x.leaf("geom", {{"name", name}, {"type", "capsule"}, {"fromto", fromto}, {"size", r}});
  };
  auto sphere = [&](const char* name, const char* pos, const char* r) {
    x.leaf("geom", {{"name", name}, {"type", "sphere"}, {"pos", pos}, {"size", r}});
  };
  // A hinge: name, pos, axis, range, stiffness, damping, armature.
  auto hinge = [&](const char* name, const char* pos, const char* axis, const char* range,
                   const char* stiffness, const char* damping, const char* armature) {
    x.leaf("joint", {{"name", name},
                     {"type", "hinge"},
                     {"pos", pos},
                     {"axis", axis},
                     {"range", range},
                     {"stiffness", stiffness},
                     {"damping", damping},
                     {"armature", armature}});
  };
  x.open("body", {{"name", "torso"}, {"pos", "0 0 .105"}});
  track_camera(x, 3.5, 2, true);
  x.leaf("joint", {{"name", "root"},
                   {"type", "free"},
                   {"armature", "0"},
                   {"damping", "0"},
                   {"limited", "false"},
                   {"pos", "0 0 0"}});
  capsule("torso1", "0 -.07 0 0 .07 0", ".07");
  sphere("head", "-.15 0 0", ".09");
  capsule("uwaist", ".11 -.06 0 .11 .06 0", ".06");
  x.open("body", {{"name", "lwaist"}, {"pos", ".21 0 0"}, {"quat", "1 0 -.002 0"}});
  capsule("lwaist", "0 -.06 0 0 .06 0", ".06");
  hinge("abdomen_z", "0 0 .065", "0 0 1", "-45 45", "20", "5", ".02");
  hinge("abdomen_y", "0 0 .065", "0 1 0", "-75 30", "10", "5", ".02");
  x.open("body", {{"name", "pelvis"}, {"pos", ".165 0 0"}, {"quat", "1 0 -.002 0"}});
  hinge("abdomen_x", "0 0 .1", "1 0 0", "-35 35", "10", "5", ".02");
  capsule("butt", "-.02 -.07 0 -.02 .07 0", ".09");
  for (const bool right : {true, false}) {
    const std::string s = right ? "right" : "left";
    const char* sign = right ? "" : "-";
    x.open("body", {{"name", s + "_thigh"}, {"pos", right ? "0 -.1 0" : "0 .1 0"}});
    hinge((s + "_hip_x").c_str(), "0 0 0", right ? "1 0 0" : "-1 0 0", "-25 5", "10", "5", ".01");
    hinge((s + "_hip_z").c_str(), "0 0 0", right ? "0 0 1" : "0 0 -1", "-60 35", "10", "5", ".01");
    hinge((s + "_hip_y").c_str(), "0 0 0", "0 1 0", right ? "-110 20" : "-120 20", "20", "5",
          right ? ".008" : ".01");
    capsule((s + "_thigh1").c_str(), right ? "0 0 0 .34 .01 0" : "0 0 0 .34 -.01 0", ".06");
    x.open("body", {{"name", s + "_shin"}, {"pos", right ? ".403 .01 0" : ".403 -.01 0"}});
    hinge((s + "_knee").c_str(), "0 0 .02", "0 -1 0", "-160 -2", right ? "0" : "1", "1", ".006");
    capsule((s + "_shin1").c_str(), "0 0 0 .3 0 0", ".049");
    x.open("body", {{"name", s + "_foot"}, {"pos", ".35 0 -.1"}});
    sphere((s + "_foot").c_str(), "0 0 .1", ".075");
    x.close().close().close();
    (void)sign;
  }
  x.close().close();
  for (const bool right : {true, false}) {
    const std::string s = right ? "right" : "left";
    x.open("body", {{"name", s + "_upper_arm"}, {"pos", right ? "0 -.17 .06" : "0 .17 .06"}});
    hinge((s + "_shoulder1").c_str(), "0 0 0", right ? "2 1 1" : "2 -1 1",
          right ? "-85 60" : "-60 85", "1", "1", ".0068");
    hinge((s + "_shoulder2").c_str(), "0 0 0", right ? "0 -1 1" : "0 1 1",
          right ? "-85 60" : "-60 85", "1", "1", ".0051");
    capsule((s + "_uarm1").c_str(), right ? "0 0 0 .16 -.16 -.16" : "0 0 0 .16 .16 -.16", ".04");
    x.open("body", {{"name", s + "_lower_arm"}, {"pos", right ? ".18 -.18 -.18" : ".18 .18 -.18"}});
    hinge((s + "_elbow").c_str(), "0 0 0", right ? "0 -1 1" : "0 -1 -1", "-90 50", "0", "1",
          ".0028");
    capsule((s + "_larm").c_str(), right ? ".01 .01 .01 .17 .17 .17" : ".01 -.01 .01 .17 -.17 .17",
            ".031");
    sphere((s + "_hand").c_str(), right ? ".18 .18 .18" : ".18 -.18 .18", ".04");
    x.close().close();
  }
  x.close().close();
  gear_motors(x, {{"abdomen_y", "100"},
                  {"abdomen_z", "100"},
                  {"abdomen_x", "100"},
                  {"right_hip_x", "100"},
                  {"right_hip_z", "100"},
                  {"right_hip_y", "300"},
                  {"right_knee", "200"},
                  {"left_hip_x", "100"},
                  {"left_hip_z", "100"},
                  {"left_hip_y", "300"},
                  {"left_knee", "200"},
                  {"right_shoulder1", "25"},
                  {"right_shoulder2", "25"},
                  {"right_elbow", "25"},
                  {"left_shoulder1", "25"},
                  {"left_shoulder2", "25"},
                  {"left_elbow", "25"}});
  x.close();
  return x.str();
}

// The velocity term reads the root x-velocity of the state the step starts from (the float32
// observation's index 22); the alive bonus needs the torso between 1 and 2 m after the step.
double reward(const LocomotionStep& s) {
  const double z = s.data->qpos[2];
  const double alive = (z < 1.0 || z > 2.0) ? 0.0 : 5.0;
  return (0.25 / 0.015) * s.start_vx - s.ctrl - 0.0 + alive;
}

// qpos but root x and y, qvel.
void observe(const mjModel* m, const mjData* d, double /*velocity*/, double* o) {
  o = std::copy_n(d->qpos + 2, m->nq - 2, o);
  std::copy_n(d->qvel, m->nv, o);
}

std::vector<TaskSet> split_sets(Split split) {
  const int s = static_cast<int>(split);
  const Values lo[3] = {{0.8, 0.9}, {0.6, 0.7}, {0.4, 0.5}};
  const Values hi[3] = {{1.0, 1.15, 1.25}, {1.5, 1.6}, {1.7, 1.8}};
  return quadrants(lo[s], hi[s]);
}

}  // namespace

const EnvDef& slim_humanoid() {
  static const EnvDef def = {
      .name = "SlimHumanoid",
      .robot = Robot::kHumanoid,
      .model = robot_model,
      .obs_size = 45,
      .action_size = 17,
      .action_low = -0.4,
      .action_high = 0.4,
      .horizon = 1000,
      .frame_skip = 5,
      .dt = 0.015,
      .varies = {.mass = true, .damping = true},
      .split_sets = split_sets,
      .locomotion = {.reward = reward,
                     .observe = observe,
                     .scale = scale_mass_and_damping,
                     .info_start_vx = true,
                     .ctrl_cost = 0.1,
                     .uniform_pos = true,
                     .uniform_vel = true,
                     .pos_noise = 0.01,
                     .vel_noise = 0.01},
  };
  return def;
}

}  // namespace cradle::sami::envs

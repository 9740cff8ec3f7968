// PandaPush (tma_sami.md §7.2, sami_models.md §3): the Franka arm pushing a cube to a goal on a
// table; the hidden parameters are the table's friction and the cube's mass, one cell of a
// friction x mass grid per sub-env. The env itself is sami/panda.h's.
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "sami/envs/env_def.h"
#include "sami/panda.h"

namespace cradle::sami {

std::vector<std::array<double, 2>> panda_cells(Split split) {
  switch (split) {
    case Split::kTrain:
      return {{0.1, 1}, {0.1, 5}, {0.1, 10}, {1, 1}, {5, 1}, {10, 1}};
    case Split::kModerate:
      return {{1, 5}, {1, 10}, {5, 5}, {5, 10}, {10, 5}, {10, 10}};
    case Split::kExtreme:
      return {{0.1, 30}, {1, 30}, {5, 30}, {10, 30}, {30, 1}, {30, 5}, {30, 10}, {30, 30}};
  }
  return {};
}

namespace envs {
namespace {

// Panda push (§3): the Franka chain of §3.3 with primitive geoms, the table, the cube and the
// goal. Link inertias are not in the sources (PyBullet derives them from meshes): each link gets
// its URDF mass and COM and the inertia of a 6 cm-radius solid sphere of that mass.
std::string robot_model() {
  XmlWriter x;
  x.open("mujoco", {{"model", "panda_push"}});
  x.leaf("compiler", {{"angle", "radian"}, {"coordinate", "local"}, {"inertiafromgeom", "false"}});
  // Elliptic friction cones: the pyramidal ones let a cube sink through a table of friction 10.
  x.leaf("option", {{"timestep", "0.002"}, {"gravity", "0 0 -9.81"}, {"cone", "elliptic"}});
  x.open("default");
  // Contacts come only from the explicit pairs below (contype 0 everywhere). Stiff contacts
  // (time constant 2 timesteps) so a resting cube sinks well under 1 mm.
  x.leaf("geom", {{"contype", "0"},
                  {"conaffinity", "0"},
                  {"condim", "3"},
                  {"solref", ".004 1"},
                  {"rgba", ".9 .9 .9 1"}});
  x.leaf("joint", {{"limited", "true"}, {"armature", ".1"}, {"damping", "0"}});
  x.close();
  scenery(x);
  x.open("worldbody");
  light(x);
  x.leaf("camera",
         {{"name", "track"}, {"pos", "0.9 -0.9 0.7"}, {"xyaxes", ".707 .707 0 -.35 .35 .87"}});
  // Geom frictions are PyBullet's per-body lateral coefficients (the table's is set per task);
  // the pairs below carry Bullet's products. The ground is a plane at its top face (z = -0.4).
  x.leaf("geom", {{"name", "ground"},
                  {"type", "plane"},
                  {"pos", "0 0 -.4"},
                  {"size", "3 3 .1"},
                  {"friction", ".5 0 0"},
                  {"material", "grid"}});
  x.leaf("geom", {{"name", "table"},
                  {"type", "box"},
                  {"pos", "-.3 0 -.2"},
                  {"size", ".55 .35 .2"},
                  {"friction", "1 0 0"},
                  {"rgba", ".55 .45 .35 1"}});
  x.open("body", {{"name", "object"}, {"pos", "0 0 .02"}});
  x.leaf("freejoint", {{"name", "object"}});
  x.leaf("inertial",
         {{"pos", "0 0 0"}, {"mass", "1"}, {"diaginertia", nums({2.667e-4, 2.667e-4, 2.667e-4})}});
  x.leaf("geom", {{"name", "object"},
                  {"type", "box"},
                  {"size", ".02 .02 .02"},
                  {"friction", ".5 0 0"},
                  {"rgba", ".1 .8 .1 1"}});
  x.close();
  // The goal: a mocap body (moved per episode in mjData) with a visual-only box.
  x.open("body", {{"name", "target"}, {"mocap", "true"}, {"pos", "0 0 .02"}});
  x.leaf("geom",
         {{"name", "target"}, {"type", "box"}, {"size", ".02 .02 .02"}, {"rgba", ".1 .8 .1 .3"}});
  x.close();
  // One URDF link: body at the joint origin (rpy as a quaternion), a hinge about local z.
  struct Link {
    const char* name;
    std::array<double, 3> pos;
    double roll;
    std::array<double, 2> range;
    double mass;
    std::array<double, 3> com;
  };
  const std::array<Link, 7> links = {{
      {"link1", {0, 0, 0.333}, 0, {-2.9671, 2.9671}, 2.7, {0, -0.04, -0.05}},
      {"link2", {0, 0, 0}, -M_PI / 2, {-1.8326, 1.8326}, 2.73, {0, -0.04, 0.06}},
      {"link3", {0, -0.316, 0}, M_PI / 2, {-2.9671, 2.9671}, 2.04, {0.01, 0.01, -0.05}},
      {"link4", {0.0825, 0, 0}, M_PI / 2, {-3.1416, 0}, 2.08, {-0.03, 0.03, 0.02}},
      {"link5", {-0.0825, 0.384, 0}, -M_PI / 2, {-2.9671, 2.9671}, 3.0, {0, 0.04, -0.12}},
      {"link6", {0, 0, 0}, M_PI / 2, {-0.0873, 3.8223}, 1.3, {0.04, 0, 0}},
      {"link7", {0.088, 0, 0}, M_PI / 2, {-2.9671, 2.9671}, 0.2, {0, 0, 0.08}},
  }};
  auto inertia = [&](double mass, std::array<double, 3> com) {
    const double i = 0.4 * mass * 0.06 * 0.06;
    x.leaf("inertial", {{"pos", nums(com)}, {"mass", num(mass)}, {"diaginertia", nums({i, i, i})}});
  };
  x.open("body", {{"name", "link0"}, {"pos", "-.6 0 0"}});
  x.leaf("geom", {{"name", "link0"},
                  {"type", "cylinder"},
                  {"pos", "0 0 .06"},
                  {"size", ".06 .06"},
                  {"friction", ".5 0 0"}});
  for (size_t k = 0; k < links.size(); ++k) {
    const Link& l = links[k];
    x.open("body", {{"name", l.name},
                    {"pos", nums(l.pos)},
                    {"quat", nums({std::cos(l.roll / 2), std::sin(l.roll / 2), 0, 0})}});
    inertia(l.mass, l.com);
    x.leaf("joint", {{"name", "joint" + std::to_string(k + 1)},
                     {"type", "hinge"},
                     {"axis", "0 0 1"},
                     {"range", nums(l.range)}});
    // A capsule from the link origin towards its COM (the collision meshes are not in the
    // sources); link7's stops 7 mm above the hand (at 0.107), which it must not swallow.
    std::array<double, 3> end = {2 * l.com[0], 2 * l.com[1], 2 * l.com[2]};
    if (k + 1 == links.size()) end = {0, 0, 0.05};
    x.leaf("geom", {{"name", l.name},
                    {"type", "capsule"},
                    {"fromto", nums({0, 0, 0, end[0], end[1], end[2]})},
                    {"size", ".05"},
                    {"friction", ".5 0 0"}});
  }
  // link8 (fixed, +0.107 along z) and the hand (yaw -pi/4) as one body.
  x.open("body", {{"name", "hand"},
                  {"pos", "0 0 .107"},
                  {"quat", nums({std::cos(-M_PI / 8), 0, 0, std::sin(-M_PI / 8)})}});
  inertia(0.81, {0, 0, 0.04});
  x.leaf("geom", {{"name", "hand"},
                  {"type", "box"},
                  {"pos", "0 0 .03"},
                  {"size", ".02 .09 .025"},
                  {"friction", ".5 0 0"}});
  x.leaf("site",
         {{"name", "grasptarget"}, {"pos", "0 0 .105"}, {"size", ".005"}, {"rgba", "1 0 0 1"}});
  // Fingers: slides along the hand's +y (left) and -y (right); their inner faces are q apart from
  // the centre, so q9 + q10 is the gap between the pads.
  for (const bool left : {true, false}) {
    const double s = left ? 1 : -1;
    x.open("body", {{"name", left ? "leftfinger" : "rightfinger"}, {"pos", "0 0 .0584"}});
    x.leaf(
        "inertial",
        {{"pos", nums({0, 0.01 * s, 0.02})}, {"mass", "0.1"}, {"diaginertia", "1e-5 1e-5 1e-5"}});
    x.leaf("joint", {{"name", left ? "finger_joint1" : "finger_joint2"},
                     {"type", "slide"},
                     {"axis", nums({0, s, 0})},
                     {"range", "0 .04"},
                     {"armature", ".01"}});
    x.leaf("geom", {{"name", left ? "leftfinger" : "rightfinger"},
                    {"type", "box"},
                    {"pos", nums({0, 0.008 * s, 0.03})},
                    {"size", ".01 .008 .02"},
                    {"friction", "1 0 0"},
                    {"rgba", ".3 .3 .3 1"}});
    x.close();
  }
  x.close();  // hand
  for (size_t k = 0; k < links.size(); ++k) x.close();
  x.close();  // link0
  x.close();  // worldbody
  // PyBullet's contacts: every robot geom against the cube and the table (link0 stands on it),
  // the cube against the table and the ground; no self-collision. Each pair's lateral friction is
  // Bullet's product of the two geoms' coefficients, clipped at 10 (the env redoes the table's
  // pairs at every reset); spinning and rolling friction are zero (condim 3).
  x.open("contact");
  const auto pair = [&](const std::string& a, const std::string& b, double mu) {
    const std::string f = num(std::min(mu, 10.0));
    x.leaf("pair", {{"geom1", a},
                    {"geom2", b},
                    {"condim", "3"},
                    {"solref", ".004 1"},
                    {"friction", f + " " + f + " 0 0 0"}});
  };
  std::vector<std::pair<std::string, double>> robot = {{"link0", 0.5}};
  for (const Link& l : links) robot.emplace_back(l.name, 0.5);
  robot.insert(robot.end(), {{"hand", 0.5}, {"leftfinger", 1.0}, {"rightfinger", 1.0}});
  for (const auto& [geom, mu] : robot) {
    pair(geom, "object", mu * 0.5);
    if (geom != "link0") pair(geom, "table", mu * 1.0);
  }
  pair("object", "table", 0.5);
  pair("object", "ground", 0.25);
  x.close();
  x.open("actuator");
  // PyBullet's motors (§3.4) as velocity servos: the env sets ctrl = 50 (q* - q) every substep;
  // a stiff kv makes the velocity follow it, limited by the panda-gym motor forces.
  const double forces[9] = {87, 87, 87, 87, 12, 120, 120, 170, 170};
  for (int k = 0; k < 9; ++k) {
    const std::string joint =
        k < 7 ? "joint" + std::to_string(k + 1) : (k == 7 ? "finger_joint1" : "finger_joint2");
    x.leaf("velocity", {{"name", joint},
                        {"joint", joint},
                        {"kv", "80"},
                        {"forcelimited", "true"},
                        {"forcerange", nums({-forces[k], forces[k]})}});
  }
  x.close().close();
  return x.str();
}

// One sub-env per friction x mass cell, as SaMI's DummyVecEnv.
std::vector<TaskSet> split_sets(Split split) {
  std::vector<TaskSet> sets;
  for (const auto& cell : panda_cells(split)) sets.push_back({.cells = {cell}});
  return sets;
}

std::unique_ptr<SamiEnv> make(Spec spec, ModelPtr model, std::vector<TaskSet> sets,
                              std::uint64_t seed, Options /*options*/) {
  return make_panda(std::move(spec), std::move(model), std::move(sets), seed);
}

}  // namespace

const EnvDef& panda_push() {
  static const EnvDef def = {
      .name = "PandaPush",
      .robot = Robot::kPanda,
      .model = robot_model,
      .obs_size = 25,
      .action_size = 4,
      .horizon = 50,
      .frame_skip = 20,
      .dt = 0.04,
      .keys = {{"observation", 0, 19}, {"achieved_goal", 19, 3}, {"desired_goal", 22, 3}},
      .varies = {.cells = true},
      .split_sets = split_sets,
      .make = make,
  };
  return def;
}

}  // namespace envs
}  // namespace cradle::sami

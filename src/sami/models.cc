#include "sami/models.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "core/xml.h"
#include "sim/mujoco_handlers.h"

namespace cradle::sami {
namespace {

constexpr const char* kVfsName = "sami.xml";

// Shared scenery: a light from above and a chequered floor material.
void scenery(XmlWriter& x) {
  x.open("asset");
  x.leaf("texture", {{"name", "grid"},
                     {"type", "2d"},
                     {"builtin", "checker"},
                     {"rgb1", ".15 .2 .25"},
                     {"rgb2", ".25 .3 .35"},
                     {"width", "256"},
                     {"height", "256"}});
  x.leaf("material",
         {{"name", "grid"}, {"texture", "grid"}, {"texrepeat", "1 1"}, {"texuniform", "true"}});
  x.close();
}

void light(XmlWriter& x) {
  x.leaf("light", {{"directional", "true"},
                   {"diffuse", ".8 .8 .8"},
                   {"pos", "0 0 5"},
                   {"dir", "0 0 -1"},
                   {"castshadow", "false"}});
}

// A tracking camera beside the robot, looking at it horizontally (pitch 0) or from above.
void track_camera(XmlWriter& x, double distance, double height, bool from_above = false) {
  x.leaf("camera", {{"name", "track"},
                    {"mode", "trackcom"},
                    {"pos", nums({0, -distance, height})},
                    {"xyaxes", from_above ? "1 0 0 0 .5 .866" : "1 0 0 0 0 1"}});
}

// The actuator section: a motor per joint, named after it, with its gear.
void gear_motors(XmlWriter& x,
                 std::initializer_list<std::pair<const char*, const char*>> joint_gears) {
  x.open("actuator");
  for (const auto& [joint, gear] : joint_gears) {
    x.leaf("motor", {{"name", joint}, {"joint", joint}, {"gear", gear}});
  }
  x.close();
}

// Half-Cheetah (sami_models.md §1.2): capsules r 0.046 given as pos, half-length and a rotation
// about y; settotalmass 14 rescales the density-1000 masses.
std::string half_cheetah() {
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

// Ant (§1.1): a sphere torso and four legs along the diagonals d_k, density 5, degrees.
std::string ant() {
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

// Planar root of the hopper and walker: x slide, z slide with ref 1.25, y hinge at the torso.
void planar_root(XmlWriter& x) {
  const Attrs free = {{"armature", "0"}, {"damping", "0"}, {"limited", "false"}};
  auto joint = [&](Attrs a) {
    a.insert(a.end(), free.begin(), free.end());
    x.leaf("joint", a);
  };
  joint({{"name", "rootx"}, {"type", "slide"}, {"axis", "1 0 0"}, {"pos", "0 0 0"}});
  joint(
      {{"name", "rootz"}, {"type", "slide"}, {"axis", "0 0 1"}, {"pos", "0 0 0"}, {"ref", "1.25"}});
  joint({{"name", "rooty"}, {"type", "hinge"}, {"axis", "0 1 0"}, {"pos", "0 0 1.25"}});
}

// One planar leg (thigh, leg, foot) in gym's global coordinates, written with gym's numbers: the
// compiler's global-to-local conversion then rounds exactly as it does for gym's file (a local
// rewrite differs from it in the last 1-3 bits of positions, masses and inertias).
void planar_leg(XmlWriter& x, const std::string& suffix, const char* foot_fromto,
                const char* foot_body_pos, const char* foot_friction) {
  x.open("body", {{"name", "thigh" + suffix}, {"pos", "0 0 1.05"}});
  x.leaf("joint", {{"name", "thigh" + suffix + "_joint"},
                   {"type", "hinge"},
                   {"pos", "0 0 1.05"},
                   {"axis", "0 -1 0"},
                   {"range", "-150 0"}});
  x.leaf("geom", {{"name", "thigh" + suffix + "_geom"},
                  {"type", "capsule"},
                  {"fromto", "0 0 1.05 0 0 0.6"},
                  {"size", "0.05"},
                  {"friction", "0.9"}});
  x.open("body", {{"name", "leg" + suffix}, {"pos", "0 0 0.35"}});
  x.leaf("joint", {{"name", "leg" + suffix + "_joint"},
                   {"type", "hinge"},
                   {"pos", "0 0 0.6"},
                   {"axis", "0 -1 0"},
                   {"range", "-150 0"}});
  x.leaf("geom", {{"name", "leg" + suffix + "_geom"},
                  {"type", "capsule"},
                  {"fromto", "0 0 0.6 0 0 0.1"},
                  {"size", "0.04"},
                  {"friction", "0.9"}});
  x.open("body", {{"name", "foot" + suffix}, {"pos", foot_body_pos}});
  x.leaf("joint", {{"name", "foot" + suffix + "_joint"},
                   {"type", "hinge"},
                   {"pos", "0 0 0.1"},
                   {"axis", "0 -1 0"},
                   {"range", "-45 45"}});
  x.leaf("geom", {{"name", "foot" + suffix + "_geom"},
                  {"type", "capsule"},
                  {"fromto", foot_fromto},
                  {"size", "0.06"},
                  {"friction", foot_friction}});
  x.close().close().close();
}

// Hopper (§1.3) and Walker2d (§1.4) in gym's global coordinates (MuJoCo 2.2.2 still reads them),
// so they compile to gym's numbers bit for bit. The hopper's foot is at (0.13, 0, 0) (SaMI's copy
// writes an expression there that MuJoCo cannot read).
std::string planar(bool walker) {
  XmlWriter x;
  x.open("mujoco", {{"model", walker ? "walker2d" : "hopper"}});
  x.leaf("compiler", {{"angle", "degree"}, {"coordinate", "global"}, {"inertiafromgeom", "true"}});
  x.open("default");
  if (walker) {
    x.leaf("joint", {{"armature", "0.01"}, {"damping", ".1"}, {"limited", "true"}});
    x.leaf("geom", {{"conaffinity", "0"},
                    {"condim", "3"},
                    {"contype", "1"},
                    {"density", "1000"},
                    {"friction", ".7 .1 .1"},
                    {"rgba", ".8 .6 .4 1"}});
  } else {
    x.leaf("joint", {{"armature", "1"}, {"damping", "1"}, {"limited", "true"}});
    x.leaf("geom", {{"conaffinity", "1"},
                    {"condim", "1"},
                    {"contype", "1"},
                    {"margin", "0.001"},
                    {"solimp", ".8 .8 .01"},
                    {"solref", ".02 1"},
                    {"rgba", ".8 .6 .4 1"}});
    x.leaf("motor", {{"ctrllimited", "true"}, {"ctrlrange", "-.4 .4"}});
  }
  x.close();
  x.leaf("option", {{"integrator", "RK4"}, {"timestep", "0.002"}});
  scenery(x);
  x.open("worldbody");
  light(x);
  Attrs floor = {
      {"name", "floor"},    {"type", "plane"}, {"size", walker ? "40 40 40" : "20 20 .125"},
      {"conaffinity", "1"}, {"condim", "3"},   {"material", "grid"}};
  if (walker) floor.push_back({"friction", ".7 .1 .1"});
  x.leaf("geom", floor);
  x.open("body", {{"name", "torso"}, {"pos", "0 0 1.25"}});
  track_camera(x, 3, 0);
  planar_root(x);
  x.leaf("geom", {{"name", "torso_geom"},
                  {"type", "capsule"},
                  {"fromto", "0 0 1.45 0 0 1.05"},
                  {"size", "0.05"},
                  {"friction", "0.9"}});
  if (walker) {
    planar_leg(x, "", "-0.0 0 0.1 0.2 0 0.1", "0.2 0 0", "0.9");
    planar_leg(x, "_left", "-0.0 0 0.1 0.2 0 0.1", "0.2 0 0", "1.9");
  } else {
    planar_leg(x, "", "-0.13 0 0.1 0.26 0 0.1", "0.13 0 0", "2.0");
  }
  x.close().close();
  x.open("actuator");
  const double gear = walker ? 100 : 200;
  for (const char* side :
       walker ? std::array<const char*, 2>{"", "_left"} : std::array<const char*, 2>{"", nullptr}) {
    if (!side) continue;
    for (const char* j : {"thigh", "leg", "foot"}) {
      const std::string joint = std::string(j) + side + "_joint";
      x.leaf("motor", {{"name", std::string(j) + side},
                       {"joint", joint},
                       {"gear", num(gear)},
                       {"ctrllimited", "true"},
                       {"ctrlrange", "-1 1"}});
    }
  }
  x.close().close();
  return x.str();
}

// The lying humanoid of humanoidstandup.xml (§1.5), used by SlimHumanoid and HumanoidStandup.
// The two fixed tendons have no dynamic effect and are left out.
std::string humanoid() {
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

// Panda push (§3): the Franka chain of §3.3 with primitive geoms, the table, the cube and the
// goal. Link inertias are not in the sources (PyBullet derives them from meshes): each link gets
// its URDF mass and COM and the inertia of a 6 cm-radius solid sphere of that mass.
std::string panda() {
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

}  // namespace

std::string robot_xml(Robot robot) {
  switch (robot) {
    case Robot::kHalfCheetah:
      return half_cheetah();
    case Robot::kAnt:
      return ant();
    case Robot::kHopper:
      return planar(false);
    case Robot::kWalker:
      return planar(true);
    case Robot::kHumanoid:
      return humanoid();
    case Robot::kPanda:
      return panda();
  }
  throw std::logic_error("unknown SaMI robot");
}

ModelPtr compile_xml(std::string_view xml) {
  // Every SaMI model is compiled here, so MuJoCo's warnings (e.g. "Nan, Inf or huge value in
  // QACC") go to stderr as one line from the first SaMI env on, never onto stdout, and its fatal
  // errors are UserErrors (sim/mujoco_handlers.h).
  sim::install_mujoco_handlers();
  // mjVFS holds fixed-size name tables (megabytes): keep it off the stack.
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  if (mj_makeEmptyFileVFS(vfs.get(), kVfsName, static_cast<int>(xml.size())) != 0) {
    mj_deleteVFS(vfs.get());
    throw std::runtime_error("cannot add the SaMI model to MuJoCo's virtual file system");
  }
  const int index = mj_findFileVFS(vfs.get(), kVfsName);
  std::copy(xml.begin(), xml.end(), static_cast<char*>(vfs->filedata[index]));
  char error[1024] = "";
  mjModel* m = mj_loadXML(kVfsName, vfs.get(), error, sizeof(error));
  mj_deleteVFS(vfs.get());
  if (!m) throw std::runtime_error(std::string("MuJoCo could not compile a SaMI model: ") + error);
  return ModelPtr(m, ModelDeleter{});
}

ModelPtr compile_robot(Robot robot) { return compile_xml(robot_xml(robot)); }

}  // namespace cradle::sami

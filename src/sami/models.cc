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
#include "sami/envs/env_def.h"
#include "sim/mujoco_handlers.h"

namespace cradle::sami {
namespace {

constexpr const char* kVfsName = "sami.xml";

}  // namespace

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

void track_camera(XmlWriter& x, double distance, double height, bool from_above) {
  x.leaf("camera", {{"name", "track"},
                    {"mode", "trackcom"},
                    {"pos", nums({0, -distance, height})},
                    {"xyaxes", from_above ? "1 0 0 0 .5 .866" : "1 0 0 0 0 1"}});
}

void gear_motors(XmlWriter& x,
                 std::initializer_list<std::pair<const char*, const char*>> joint_gears) {
  x.open("actuator");
  for (const auto& [joint, gear] : joint_gears) {
    x.leaf("motor", {{"name", joint}, {"joint", joint}, {"gear", gear}});
  }
  x.close();
}

namespace {

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

}  // namespace

// Hopper (§1.3) and Walker2d (§1.4) in gym's global coordinates (MuJoCo 2.2.2 still reads them),
// so they compile to gym's numbers bit for bit. The hopper's foot is at (0.13, 0, 0) (SaMI's copy
// writes an expression there that MuJoCo cannot read).
std::string planar_robot(bool walker) {
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

std::string robot_xml(Robot robot) {
  // The registration table's env that gives the robot's text.
  for (EnvId id : all_envs()) {
    const EnvDef& def = env_def(id);
    if (def.robot == robot && def.model) return def.model();
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

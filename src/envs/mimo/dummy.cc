// MIMoBench-v0, MIMoBenchV2-v0 and MIMoShowroom-v0 (mimo_core.md §6.5, the reference's dummy.py):
// MIMo with every sense at its defaults and no task (reward 0, episodes end only at the time
// limit), for benchmarks and demos. The benchmark drops MIMo on the floor next to a box and a
// bouncy ball; the showroom is a walled room with toys.
#include <string>
#include <utility>

#include "envs/mimo/sample_env.h"

namespace cradle::envs {
namespace {

// No task: reward 0, never a success or a failure.
class NoTask final : public SampleTask {
 public:
  double after_step(const MimoCore&, Info&) override { return 0; }
};

std::unique_ptr<Task> make_no_task(MimoCore&, const SampleOptions&) {
  return std::make_unique<NoTask>();
}

SampleDefinition dummy(std::string name, int max_steps, model::MimoVersion version) {
  SampleDefinition def{
      .name = std::move(name), .max_episode_steps = max_steps, .vestibular = true, .vision = true};
  def.touch = senses::default_touch_scales(version, GroupFlags::all(true), 1.0);
  def.make = make_no_task;
  return def;
}

// A free body with one geom of the given type, size and extra attributes.
std::string free_body(const std::string& name, const std::string& pos, const std::string& geom) {
  return "<body name=\"" + name + "\" pos=\"" + pos + "\">\n<freejoint/>\n<geom " + geom +
         "/>\n</body>\n";
}

}  // namespace

SampleDefinition bench_definition(bool v2) {
  const model::MimoVersion version = v2 ? model::MimoVersion::kV2 : model::MimoVersion::kV1;
  SampleDefinition def = dummy(v2 ? "MIMoBenchV2-v0" : "MIMoBench-v0", 6000, version);
  def.camera_lookat = {0.5, 0, 0.2};
  def.camera_distance = 2.5;
  def.scene = [version](const SampleOptions&) {
    scene::Composition c;
    c.version = version;
    c.worlds = {sample_floor()};
    c.placement = {{0, 0, 0.4}, {1, 0, 0, 0}};
    scene::WorldFragments task;
    task.worldbody =
        free_body("box", "1 0.3 0.7", "type=\"box\" size=\"0.1 0.1 0.1\" rgba=\".8 .6 .2 1\"") +
        free_body("ball", "1 -0.3 0.7",
                  "type=\"sphere\" size=\"0.1\" rgba=\".2 .4 .8 1\" solref=\"-20000 -20\"");
    c.worlds.push_back(std::move(task));
    return c;
  };
  return def;
}

SampleDefinition showroom_definition() {
  SampleDefinition def = dummy("MIMoShowroom-v0", 500, model::MimoVersion::kV2);
  def.camera_lookat = {0, 0, 0.3};
  def.camera_distance = 2.5;
  def.camera_elevation = -30;
  def.scene = [](const SampleOptions&) {
    scene::Composition c;
    c.version = model::MimoVersion::kV2;
    c.placement = {{0, 0, 0.5}, {1, 0, 0, 0}};
    c.density = 1.2;  // air
    c.visual = "<headlight active=\"0\"/>\n";
    scene::WorldFragments room = sample_floor();
    // No top light from the floor fragment: four shadow-casting spots and a dim sky instead.
    room.worldbody = room.worldbody.substr(room.worldbody.find("<geom"));
    room.worldbody +=
        "<light directional=\"true\" diffuse=\".2 .2 .2\" specular=\"0 0 0\" pos=\"0 0 3\" "
        "dir=\"0 0 -1\" castshadow=\"false\"/>\n";
    for (const char* xy : {"1.5 1.5", "1.5 -1.5", "-1.5 1.5", "-1.5 -1.5"}) {
      room.worldbody += std::string("<light mode=\"targetbodycom\" target=\"mimo_location\" ") +
                        "diffuse=\".35 .35 .35\" specular=\".1 .1 .1\" pos=\"" + xy +
                        " 1.2\" cutoff=\"60\" castshadow=\"true\"/>\n";
    }
    // Walls of a 4 m x 4 m room.
    for (const char* wall :
         {"2 0 1\" euler=\"0 0 90", "-2 0 1\" euler=\"0 0 90", "0 2 1", "0 -2 1"}) {
      room.worldbody += std::string("<geom type=\"box\" size=\"2 0.1 1\" pos=\"") + wall +
                        "\" rgba=\".9 .85 .75 1\"/>\n";
    }
    // Loose toys (density 200) and a castle of blocks.
    const std::string toy = "density=\"200\" condim=\"6\" solimp=\"0.9995 0.9999 0.001 0.5 2\" ";
    room.worldbody +=
        free_body("cube1", "0.4 0.3 0.05",
                  toy + "type=\"box\" size=\"0.03 0.03 0.03\" rgba=\".8 .2 .2 1\"") +
        free_body("cube2", "0.5 -0.2 0.05",
                  toy + "type=\"box\" size=\"0.03 0.03 0.03\" rgba=\".2 .6 .2 1\"") +
        free_body("cube3", "0.3 -0.4 0.05",
                  toy + "type=\"box\" size=\"0.02 0.02 0.02\" rgba=\".9 .8 .2 1\"") +
        free_body(
            "sphere1", "0.6 0.1 0.05",
            toy + "type=\"sphere\" size=\"0.025\" rgba=\".2 .3 .9 1\" solref=\"-20000 -20\"") +
        free_body("sphere2", "0.35 0.5 0.05",
                  toy + "type=\"sphere\" size=\"0.02\" rgba=\".9 .4 .1 1\" solref=\"-20000 -20\"") +
        free_body("sphere3", "-0.3 0.5 0.05",
                  toy + "type=\"sphere\" size=\"0.015\" rgba=\".6 .2 .7 1\" solref=\"-20000 -20\"");
    // Castle: four pillars, a roof slab, a tower, its top and a flag block.
    const char* blocks[][2] = {
        {"1 -1 0.05", "0.05 0.05 0.05"},       {"1.2 -1 0.05", "0.05 0.05 0.05"},
        {"1 -1.2 0.05", "0.05 0.05 0.05"},     {"1.2 -1.2 0.05", "0.05 0.05 0.05"},
        {"1.1 -1.1 0.125", "0.15 0.15 0.025"}, {"1.1 -1.1 0.2", "0.05 0.05 0.05"},
        {"1.1 -1.1 0.3", "0.03 0.03 0.05"},    {"1.1 -1.1 0.37", "0.02 0.02 0.02"}};
    int k = 0;
    for (const auto& [pos, size] : blocks) {
      room.worldbody += free_body("castle" + std::to_string(k++), pos,
                                  toy + "type=\"box\" size=\"" + size + "\" rgba=\".7 .6 .5 1\"");
    }
    c.worlds = {std::move(room)};
    return c;
  };
  return def;
}

}  // namespace cradle::envs

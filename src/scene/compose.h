// The composer: config -> one self-contained MJCF scene (infant + world) -> compiled mjModel.
// The scene text and its generated texture files can be written to a folder (scene.xml beside
// tex_*.png) or compiled straight from memory through MuJoCo's virtual file system.
#pragma once

#include <mujoco/mujoco.h>

#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/config.h"
#include "model/infant.h"
#include "model/mjcf.h"
#include "scene/world.h"

namespace cradle::scene {

struct SceneFiles {
  std::string xml;                                                        // scene.xml
  std::vector<std::pair<std::string, std::vector<std::uint8_t>>> assets;  // file name -> bytes
};

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
using ModelPtr = std::unique_ptr<mjModel, ModelDeleter>;

// MIMo version a behaviour uses: v2 (five fingers) for hand regard, v1 otherwise.
model::MimoVersion mimo_version_for(Behavior behavior);

// The scene for a config; the config is embedded as a YAML comment at the top.
SceneFiles compose_scene(const Config& config);

// Everything a scene is made of: MIMo (version and emitter options) on his free joint at
// `placement`, inside worlds whose fragments are placed in order.
struct Composition {
  std::string comment;  // XML comment at the top
  model::MimoVersion version = model::MimoVersion::kV1;
  model::EmitOptions emit;
  std::vector<WorldFragments> worlds;
  Placement placement;
  std::string visual;   // children of <visual> besides <global>
  int offscreen = 480;  // offscreen buffer edge (px)
  std::array<double, 3> gravity{0, 0, -9.81};
  double density = 0;  // of the medium (kg/m^3), e.g. 1.2 for air
  // MuJoCo 2.2.2's preallocated sizes: each mjData holds nconmax contacts, dense constraint
  // arrays of njmax rows (njmax^2 doubles among them) and nstack doubles of stack.
  int nconmax = 1000, njmax = 5000, nstack = 2000000;
};

// The sizes of a BabyBench scene: the measured maxima (random actions from random starts) with a
// safety margin, so an env takes a few MB instead of the reference's ~300 (docs/
// babybench-physics.md). An overflow ends the episode cleanly (sim::Sim::overflows()).
struct SceneSizes {
  int nconmax, njmax, nstack;
};
SceneSizes scene_sizes(SceneKind kind);
// The scene text and texture files of a composition.
SceneFiles compose(const Composition& composition);

// Compiles from memory. Throws std::runtime_error with MuJoCo's message on failure.
ModelPtr compile_scene(const SceneFiles& scene);

// Writes scene.xml and its texture files into dir (created if missing). Throws UserError if the
// folder cannot be written.
void write_scene(const SceneFiles& scene, const std::filesystem::path& dir);

// Loads a scene.xml written by write_scene (or any MJCF file). Throws UserError naming the file.
ModelPtr load_scene(const std::filesystem::path& file);

inline constexpr const char* kSceneFileName = "scene.xml";
// A results folder keeps its scene (scene.xml and the texture PNGs) in this subfolder, so that its
// top level reads logs, checkpoints, plots, videos and evaluation.
inline constexpr const char* kSceneDirName = "scene";

}  // namespace cradle::scene

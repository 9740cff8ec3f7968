// `cradle build-scene --config FILE [--out DIR]`: writes scene.xml and its textures (into
// <save_dir>/scene/, or into DIR).
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include "apps/commands.h"
#include "core/config.h"
#include "scene/compose.h"
#include "scene/summary.h"

namespace cradle::apps {

void register_build_scene(CLI::App& app) {
  struct Options {
    std::string config;
    std::string out;
  };
  auto opts = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "build-scene", "Write <save_dir>/scene/scene.xml (or <out>/scene.xml) and its texture files");
  cmd->add_option("--config", opts->config, "BabyBench YAML config")->required();
  cmd->add_option("--out", opts->out, "Output folder (default: the config's save_dir)");
  cmd->callback([opts] {
    const Config config = load_config(opts->config);
    // A results folder keeps its scene in scene/; --out is the folder itself.
    const std::filesystem::path dir =
        opts->out.empty() ? std::filesystem::path(config.save_dir) / scene::kSceneDirName
                          : std::filesystem::path(opts->out);
    const scene::SceneFiles files = scene::compose_scene(config);
    // Compile before writing so a broken scene never lands on disk.
    const scene::ModelPtr model = scene::compile_scene(files);
    scene::write_scene(files, dir);
    const scene::ModelSummary s = scene::summarize(model.get());
    std::printf("wrote %s (%zu texture files): MIMo %s, %d joints, %d actuators, %.3f kg\n",
                (dir / scene::kSceneFileName).c_str(), files.assets.size(), s.mimo_version.c_str(),
                s.n_joints, s.n_actuators, s.total_mass);
  });
}

}  // namespace cradle::apps

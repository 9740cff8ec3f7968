// `cradle model-info --config FILE [--json]`: what the config's compiled model contains.
#include <cstdio>
#include <memory>
#include <string>

#include "apps/commands.h"
#include "core/config.h"
#include "envs/babybench.h"
#include "scene/compose.h"
#include "scene/summary.h"
#include "sim/actuation.h"

namespace cradle::apps {

void register_model_info(CLI::App& app) {
  struct Options {
    std::string config;
    bool json = false;
  };
  auto opts = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("model-info", "Print the compiled model's counts and sizes");
  cmd->add_option("--config", opts->config, "BabyBench YAML config")->required();
  cmd->add_flag("--json", opts->json, "Print one JSON object");
  cmd->callback([opts] {
    const Config config = load_config(opts->config);
    const auto assets = envs::make_assets(config);
    const scene::ModelSummary s = scene::summarize(assets->model.get());
    // Spaces come from the same code the env uses, without building an env (no GL needed).
    const auto actuation = sim::make_actuation(config.actuation_model, assets->model.get());
    const DictSpace obs = envs::babybench_observation_space(*assets, actuation->observation_size());
    nlohmann::ordered_json sizes;
    for (const auto& [key, box] : obs.entries) sizes[key] = box.size();
    const int action_dim = actuation->action_space().size();
    if (opts->json) {
      nlohmann::json j = scene::to_json(s);
      j["action_dim"] = action_dim;
      j["observation_sizes"] = sizes;
      if (assets->touch) j["touch_sensors"] = assets->touch->sensor_count();
      std::printf("%s\n", j.dump(2).c_str());
      return;
    }
    std::printf("MIMo %s in scene '%s' (behavior %s, actuation %s)\n", s.mimo_version.c_str(),
                std::string(scene_name(config.scene)).c_str(),
                std::string(behavior_name(config.behavior)).c_str(),
                std::string(actuation_model_name(config.actuation_model)).c_str());
    std::printf("  joints %d, actuators %d, torque sensors %d, bodies %d, geoms %d\n", s.n_joints,
                s.n_actuators, s.n_torque_sensors, s.n_bodies, s.n_geoms);
    std::printf("  total mass %.4f kg, height %.4f m\n", s.total_mass, s.height);
    std::printf("  MuJoCo: nq %d, nv %d, nu %d, nbody %d, ngeom %d, neq %d, ncam %d\n", s.nq, s.nv,
                s.nu, s.nbody, s.ngeom, s.neq, s.ncam);
    std::printf("  texture data %.2f MB, timestep %g s\n", s.ntexdata / 1e6, s.timestep);
    std::printf("  action dim %d; observation sizes %s\n", action_dim, sizes.dump().c_str());
  });
}

}  // namespace cradle::apps

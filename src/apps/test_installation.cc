// `cradle test-installation [--save-dir DIR]`: the reference's test_installation.py. Builds the
// test_installation config (built in), steps it with random actions while filming the corner
// camera, and writes <save_dir>/{scene/scene.xml, logs/training.jsonl,
// videos/test_installation.mp4}.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "apps/commands.h"
#include "core/config.h"
#include "core/error.h"
#include "core/rng.h"
#include "envs/babybench.h"
#include "eval/video.h"
#include "train/frames.h"

namespace cradle::apps {

void register_test_installation(CLI::App& app) {
  struct Options {
    std::string save_dir;
    int steps = 10;
  };
  auto opts = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "test-installation", "Check that Cradle works here: build, simulate, sense, render, encode");
  cmd->add_option("--out,--save-dir", opts->save_dir,
                  "Output folder (default: results/test_installation)");
  cmd->add_option("--steps", opts->steps, "Random steps after the first one")
      ->check(CLI::Range(1, 100000));
  cmd->callback([opts] {
    Config config = test_installation_config();
    if (!opts->save_dir.empty()) config.save_dir = opts->save_dir;
    const std::filesystem::path dir = config.save_dir;
    try {
      auto env = envs::make_env(config, /*training=*/true);
      env->reset(0);
      train::FrameComposer composer(*env);
      std::vector<std::uint8_t> image(480 * 480 * 3);
      eval::VideoWriter video(dir / "videos" / "test_installation.mp4", 480, 480, 60);
      const Box& space = env->action_space();
      std::vector<double> action(space.size());
      Rng rng(1);
      for (int t = 0; t < 1 + opts->steps; ++t) {
        space.sample(rng, action);
        env->step(action);
        composer.corner(*env, image);
        video.write(image);
      }
      video.close();
      env->close();
      std::printf(
          "Cradle installation test passed: %d steps with touch (%d sensors), vision "
          "(%dx%d eyes), vestibular and proprioception (%d values)\n",
          1 + opts->steps, env->touch() ? env->touch()->sensor_count() : 0,
          config.vision_resolution, config.vision_resolution,
          env->observation_space().find("observation")->size());
      std::printf("wrote %s/{scene/scene.xml, logs/training.jsonl, videos/test_installation.mp4}\n",
                  dir.c_str());
    } catch (const UserError&) {
      throw;
    } catch (const std::exception& e) {
      throw UserError(std::string("installation test failed: ") + e.what());
    }
  });
}

}  // namespace cradle::apps

// `cradle tma random|bench|info`: TeachMyAgent's environments from the command line.
//   random --env stump-tracks|parkour --embodiment E [--task k=v ...] [--video out.mp4]
//          [--steps N] [--seed S] [--png F]: one random-policy episode (return, length, success);
//   bench  --env ... --embodiment E|all [--steps N] [--json]: env steps/s and the ratio to the
//          bare b2World::Step on the same world, measured in one run, plus the reset time;
//   info   : observation / action sizes and masses of every embodiment in both envs (JSON).
#include <chrono>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "apps/commands.h"
#include "core/error.h"
#include "core/image.h"
#include "core/rng.h"
#include "eval/video.h"
#include "model/textures.h"
#include "tma/render.h"
#include "tma/tma_env.h"

namespace cradle::apps {
namespace {

// "name=v" or "name=v1,v2,v3" -> a task parameter; anything else is a one-line error.
tma::TaskParam parse_task(const std::string& text) {
  const size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size()) {
    throw UserError("--task '" + text + "' (expected name=value or name=v1,v2,v3)");
  }
  tma::TaskParam p{text.substr(0, eq), {}};
  std::string rest = text.substr(eq + 1);
  size_t start = 0;
  while (start <= rest.size()) {
    const size_t comma = rest.find(',', start);
    const std::string item = rest.substr(start, comma - start);
    try {
      size_t used = 0;
      p.second.push_back(std::stod(item, &used));
      if (used != item.size()) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw UserError("--task '" + text + "': '" + item + "' is not a number");
    }
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return p;
}

struct BenchResult {
  double env_steps_per_s = 0, bare_steps_per_s = 0, ratio = 0, reset_ms = 0, mass = 0;
};

// Env steps with random actions (resets not timed), then bare world steps on the same world.
BenchResult bench_one(tma::EnvId id, const std::string& body, int steps, std::uint64_t seed) {
  using Clock = std::chrono::steady_clock;
  tma::TmaEnv env(tma::TmaOptions{.env = id, .body = body});
  if (id == tma::EnvId::kStumpTracks) {
    env.set_environment({{"stump_height", {1.0}}, {"obstacle_spacing", {3.0}}});
  } else {
    env.set_environment({{"input_vector", {-0.15, 0.8, 0.1}},
                         {"water_level", {body == "fish" ? 1.0 : 0.1}},
                         {"creepers_width", {0.25}},
                         {"creepers_height", {2.0}},
                         {"creepers_spacing", {2.5}}});
  }
  BenchResult r;
  const int resets = 20;
  const Clock::time_point t0 = Clock::now();
  for (int i = 0; i < resets; ++i) env.reset(seed + i);
  r.reset_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count() / resets;
  r.mass = env.agent().mass();

  env.reset(seed);
  Rng rng(seed + 1);
  std::vector<double> action(env.action_size());
  double env_s = 0;
  for (int i = 0; i < steps; ++i) {
    for (double& a : action) a = rng.uniform(-1, 1);
    const Clock::time_point t = Clock::now();
    const tma::TmaStep s = env.step(action);
    env_s += std::chrono::duration<double>(Clock::now() - t).count();
    if (s.terminated || s.truncated) env.reset();
  }
  // Bare: the same world, motors driven at random, only b2World::Step timed.
  env.reset(seed);
  double bare_s = 0;
  for (int i = 0; i < steps; ++i) {
    for (double& a : action) a = rng.uniform(-1, 1);
    env.agent().activate_motors(action);
    const Clock::time_point t = Clock::now();
    env.world().Step(static_cast<float>(1.0 / tma::kFps), tma::kVelocityIterations,
                     tma::kPositionIterations);
    bare_s += std::chrono::duration<double>(Clock::now() - t).count();
    if (i % 500 == 499) env.reset();  // keep the bare world near the same states as the env's
  }
  r.env_steps_per_s = steps / env_s;
  r.bare_steps_per_s = steps / bare_s;
  r.ratio = env_s / bare_s;
  return r;
}

}  // namespace

void register_tma(CLI::App& app) {
  CLI::App* tma_cmd = app.add_subcommand("tma", "TeachMyAgent environments (Box2D)");
  tma_cmd->require_subcommand(1);

  struct RandomOptions {
    std::string env = "stump-tracks", body = "old_classic_bipedal", video, png;
    int png_step = 60;
    std::vector<std::string> tasks;
    int steps = tma::kMaxEpisodeSteps;
    std::uint64_t seed = 0;
    bool movable_creepers = false, lidars = false;
  };
  auto ro = std::make_shared<RandomOptions>();
  CLI::App* random = tma_cmd->add_subcommand("random", "One random-policy episode");
  random->add_option("--env", ro->env, "stump-tracks | parkour (or the reference ids)");
  random->add_option("--embodiment", ro->body, "Embodiment (see `cradle tma info`)");
  random->add_option("--task", ro->tasks, "Task parameter name=value[,v2,v3] (repeatable)");
  random->add_option("--video", ro->video, "Write the episode to this .mp4 / .avi");
  random->add_option("--steps", ro->steps, "Episode step cap")->check(CLI::Range(1, 1000000));
  random->add_option("--seed", ro->seed, "Seed of the env and the policy");
  random->add_flag("--movable-creepers", ro->movable_creepers, "Parkour: dynamic creepers");
  random->add_flag("--lidars", ro->lidars, "Draw the lidar rays in the video");
  random->add_option("--png", ro->png, "Save the frame after --png-step steps as PNG");
  random->add_option("--png-step", ro->png_step, "Step of the --png frame (or the last step)")
      ->check(CLI::Range(0, 1000000));
  random->callback([ro] {
    tma::TmaEnv env(tma::TmaOptions{.env = tma::parse_env_id(ro->env),
                                    .body = ro->body,
                                    .movable_creepers = ro->movable_creepers,
                                    .max_episode_steps = ro->steps});
    std::vector<tma::TaskParam> params;
    for (const std::string& t : ro->tasks) params.push_back(parse_task(t));
    env.set_environment(params);
    env.reset(ro->seed);
    std::unique_ptr<eval::VideoWriter> video;
    std::vector<std::uint8_t> frame;
    const int w = 600, h = 400;
    if (!ro->video.empty()) {
      video = std::make_unique<eval::VideoWriter>(ro->video, w, h, tma::kFps);
      tma::render(env, w, h, ro->lidars, frame);
      video->write(frame);
    }
    Rng rng(ro->seed + 1);
    std::vector<double> action(env.action_size());
    tma::TmaStep s;
    auto snapshot = [&] {
      model::Image image{.width = w, .height = h};
      tma::render(env, w, h, ro->lidars, image.rgb);
      write_png(image, ro->png);
    };
    if (!ro->png.empty() && ro->png_step == 0) snapshot();
    do {
      for (double& a : action) a = rng.uniform(-1, 1);
      s = env.step(action);
      const bool last = s.terminated || s.truncated;
      if (!ro->png.empty() &&
          (env.episode_steps() == ro->png_step || (last && env.episode_steps() < ro->png_step))) {
        snapshot();
      }
      if (video) {
        tma::render(env, w, h, ro->lidars, frame);
        video->write(frame);
      }
    } while (!s.terminated && !s.truncated);
    if (video) video->close();
    std::printf("%s %s: %d steps, return %.3f, success %s, %s\n",
                std::string(tma::env_id_name(env.options().env)).c_str(), ro->body.c_str(),
                env.episode_steps(), env.episode_return(), s.success ? "true" : "false",
                s.terminated ? "terminated" : "truncated");
    if (video) std::printf("video: %s (%d frames)\n", ro->video.c_str(), video->frames());
  });

  struct BenchOptions {
    std::string env = "stump-tracks", body = "old_classic_bipedal";
    int steps = 20000;
    std::uint64_t seed = 0;
    bool json = false;
  };
  auto bo = std::make_shared<BenchOptions>();
  CLI::App* bench = tma_cmd->add_subcommand("bench", "Env steps/s vs bare b2World::Step");
  bench->add_option("--env", bo->env, "stump-tracks | parkour");
  bench->add_option("--embodiment", bo->body, "Embodiment, or all");
  bench->add_option("--steps", bo->steps, "Steps timed")->check(CLI::Range(100, 100000000));
  bench->add_option("--seed", bo->seed, "Seed");
  bench->add_flag("--json", bo->json, "JSON output");
  bench->callback([bo] {
    const tma::EnvId id = tma::parse_env_id(bo->env);
    std::vector<std::string> bodies;
    if (bo->body == "all") {
      bodies = tma::embodiment_names();
    } else {
      bodies = {tma::embodiment(bo->body).name};
    }
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    for (const std::string& body : bodies) {
      const BenchResult r = bench_one(id, body, bo->steps, bo->seed);
      if (bo->json) {
        out.push_back({{"env", tma::env_id_name(id)},
                       {"embodiment", body},
                       {"steps", bo->steps},
                       {"env_steps_per_s", r.env_steps_per_s},
                       {"bare_steps_per_s", r.bare_steps_per_s},
                       {"ratio", r.ratio},
                       {"reset_ms", r.reset_ms}});
      } else {
        std::printf("%-34s env %8.0f steps/s  bare %8.0f Step/s  ratio %.2f  reset %.2f ms\n",
                    body.c_str(), r.env_steps_per_s, r.bare_steps_per_s, r.ratio, r.reset_ms);
      }
    }
    if (bo->json) std::printf("%s\n", out.dump(2).c_str());
  });

  CLI::App* info = tma_cmd->add_subcommand("info", "Spaces and masses per embodiment (JSON)");
  info->callback([] {
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    for (const std::string& body : tma::embodiment_names()) {
      tma::TmaEnv stump(tma::TmaOptions{.env = tma::EnvId::kStumpTracks, .body = body});
      tma::TmaEnv parkour(tma::TmaOptions{.env = tma::EnvId::kParkour, .body = body});
      out.push_back(
          {{"embodiment", body},
           {"type", tma::kind_name(tma::embodiment(body).kind)},
           {"action_size", stump.action_size()},
           {"observation_size",
            {{"stump-tracks", stump.observation_size()}, {"parkour", parkour.observation_size()}}},
           {"mass", stump.agent().mass()},
           {"parts", stump.agent().parts.size()}});
    }
    std::printf("%s\n", out.dump(2).c_str());
  });
}

}  // namespace cradle::apps

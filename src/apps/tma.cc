// `cradle tma random|bench|info|run`: TeachMyAgent's environments from the command line.
//   run    --env ... --embodiment E --student sac|ppo --teacher T [...]: a student trained with a
//          teacher, the reference's run.py (train/tma_student.h; run folder in docs/tma_run.md);
//   random --env stump-tracks|parkour --embodiment E [--task k=v ...] [--video out.mp4]
//          [--steps N] [--seed S] [--png F]: one random-policy episode (return, length, success);
//   run and random also take run.py's body and Parkour options (--motors_torque, --nb_of_bodies,
//          --nb_pairs_of_legs, --under_water, --outside_water, --CPPN_weights_path,
//          --input_CPPN_dim, --ceiling_offset, --ceiling_clip_offset);
//   bench  --env ... --embodiment E|all [--steps N] [--json]: env steps/s and the ratio to the
//          bare b2World::Step replaying the env's motor commands (apps/tma_bench.h), plus the
//          reset time;
//   info   : observation / action sizes and masses of every embodiment in both envs (JSON).
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "apps/bench_report.h"
#include "apps/cli_checks.h"
#include "apps/commands.h"
#include "apps/distributed_flags.h"
#include "apps/interrupt.h"
#include "apps/tma_bench.h"
#include "core/error.h"
#include "core/image.h"
#include "core/rng.h"
#include "envs/tma/tma_env.h"
#include "eval/video.h"
#include "model/textures.h"
#include "tma/cppn.h"
#include "tma/render.h"
#include "tma/tma_env.h"
#include "train/tma_student.h"

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

// The source tree's commit (through the data folder it ships), or "unknown".
std::string source_commit() {
  const std::filesystem::path dir = tma::data_dir();
  const std::string command = "git -C '" + dir.string() + "' rev-parse HEAD 2>/dev/null";
  std::FILE* pipe = popen(command.c_str(), "r");
  if (!pipe) return "unknown";
  char buf[64] = "";
  const bool read = std::fgets(buf, sizeof buf, pipe) != nullptr;
  pclose(pipe);
  std::string out = read ? buf : "";
  while (!out.empty() && (out.back() == '\n' || out.back() == '\r')) out.pop_back();
  return out.size() == 40 ? out : "unknown";
}

// run.py's body and Parkour options, kept as text and parsed by tma::set_option (one check for the
// CLI and Python). run.py names the water limits --under_water and --outside_water.
struct EnvFlags {
  struct Flag {
    const char* option;  // TmaOptions name
    const char* names;   // CLI11 names
    const char* help;
  };
  static constexpr Flag kFlags[] = {
      {"motors_torque", "--motors_torque",
       "Max motor torque at |action| = 1 (default: the body's)"},
      {"nb_of_bodies", "--nb_of_bodies", "Millipede: segments, one pair of legs each (4)"},
      {"nb_pairs_of_legs", "--nb_pairs_of_legs", "Spider: pairs of legs (2)"},
      {"nb_steps_under_water", "--under_water,--nb_steps_under_water",
       "Walkers, climbers: steps under water before drowning (600)"},
      {"nb_steps_outside_water", "--outside_water,--nb_steps_outside_water",
       "Fish: steps out of water before stranding (600)"},
      {"CPPN_weights_path", "--CPPN_weights_path",
       "Parkour: CPPN weights, a raw float32 file or a TensorFlow checkpoint prefix"},
      {"input_CPPN_dim", "--input_CPPN_dim", "Parkour: the CPPN's input dimension (3)"},
      {"ceiling_offset", "--ceiling_offset",
       "Parkour: ceiling height above the start pad, in CPPN units (200)"},
      {"ceiling_clip_offset", "--ceiling_clip_offset",
       "Parkour: least ceiling height above the ground, in CPPN units (0)"},
  };
  std::map<std::string, std::string> text;
  std::vector<std::pair<std::string, const CLI::Option*>> given;

  void add(CLI::App* cmd) {
    for (const Flag& f : kFlags)
      given.emplace_back(f.option, cmd->add_option(f.names, text[f.option], f.help));
  }
  void apply(tma::TmaOptions& o) const {
    for (const auto& [name, option] : given) {
      if (option->count() > 0) tma::set_option(o, name, text.at(name));
    }
  }
  // The options given, as text by their TmaOptions names.
  std::map<std::string, std::string> given_text() const {
    std::map<std::string, std::string> out;
    for (const auto& [name, option] : given) {
      if (option->count() > 0) out[name] = text.at(name);
    }
    return out;
  }
};

// `tma run`'s flags: run.py's arguments (train::TmaRunArguments) and the CLI's own.
struct RunOptions {
  train::TmaRunArguments a;
  bool no_progress = false;
  EnvFlags env_flags;
  DistributedFlags dist;
};

// The environment and embodiment options of `random` and `run`.
void add_env_options(CLI::App* cmd, std::string& env, std::string& body) {
  cmd->add_option("--env", env, "stump-tracks | parkour (or the reference ids)");
  cmd->add_option("--embodiment", body, "Embodiment (see `cradle tma info`)");
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
    EnvFlags env_flags;
  };
  auto ro = std::make_shared<RandomOptions>();
  CLI::App* random = tma_cmd->add_subcommand("random", "One random-policy episode");
  add_env_options(random, ro->env, ro->body);
  ro->env_flags.add(random);
  random->add_option("--task", ro->tasks, "Task parameter name=value[,v2,v3] (repeatable)");
  random->add_option("--video", ro->video, "Write the episode to this .mp4 / .avi");
  random->add_option("--steps", ro->steps, "Episode step cap")->check(CLI::Range(1, 1000000));
  random->add_option("--seed", ro->seed, "Seed of the env and the policy")->check(kSeed);
  random->add_flag("--movable-creepers", ro->movable_creepers, "Parkour: dynamic creepers");
  random->add_flag("--lidars", ro->lidars, "Draw the lidar rays in the video");
  random->add_option("--png", ro->png, "Save the frame after --png-step steps as PNG");
  random->add_option("--png-step", ro->png_step, "Step of the --png frame (or the last step)")
      ->check(CLI::Range(0, 1000000));
  random->callback([ro] {
    tma::TmaOptions options{.env = tma::parse_env_id(ro->env),
                            .body = ro->body,
                            .movable_creepers = ro->movable_creepers,
                            .max_episode_steps = ro->steps};
    ro->env_flags.apply(options);
    tma::TmaEnv env(options);
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
  CLI::App* bench = tma_cmd->add_subcommand(
      "bench",
      "Env steps/s vs bare b2World::Step replaying the env's motor commands from the same state, "
      "in alternating blocks (CPU time; ratio: the blocks' median and range)");
  bench->add_option("--env", bo->env, "stump-tracks | parkour");
  bench->add_option("--embodiment", bo->body, "Embodiment, or all");
  bench->add_option("--steps", bo->steps, "Steps timed")->check(CLI::Range(100, 100000000));
  bench->add_option("--seed", bo->seed, "Seed")->check(kSeed);
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
      const TmaBenchResult r = tma_bench(id, body, bo->steps, bo->seed);
      const Spread& ratio = r.timing.ratio;
      if (bo->json) {
        out.push_back({{"env", tma::env_id_name(id)},
                       {"embodiment", body},
                       {"steps", bo->steps},
                       {"env_steps_per_s", r.env_steps_per_s},
                       {"bare_steps_per_s", r.bare_steps_per_s},
                       {"ratio", r.ratio}});
        add_block_timing(out.back(), r.timing, r.env_us, r.bare_us);
        out.back()["reset_ms"] = r.reset_ms;
      } else {
        std::printf(
            "%-34s env %8.0f steps/s  bare %8.0f Step/s  ratio %.2f (%.2f-%.2f)  reset %.2f ms  "
            "replay %s\n",
            body.c_str(), r.env_steps_per_s, r.bare_steps_per_s, r.ratio, ratio.min, ratio.max,
            r.reset_ms, r.timing.replay_exact ? "exact" : "inexact");
      }
    }
    if (bo->json) std::printf("%s\n", out.dump(2).c_str());
  });

  auto rn = std::make_shared<RunOptions>();
  CLI::App* run = tma_cmd->add_subcommand("run", "Train a student with a teacher (run.py)");
  run->add_option("--exp_name", rn->a.exp_name, "Experiment name (default run folder)");
  add_env_options(run, rn->a.env, rn->a.body);
  rn->env_flags.add(run);
  run->add_option("--student,--algo", rn->a.student, "sac | ppo (the reference presets)");
  run->add_option("--teacher", rn->a.teacher,
                  "Random, ADR, ALP-GMM, Covar-GMM, RIAC, Self-Paced, GoalGAN, Setter-Solver");
  run->add_option("--teacher-param", rn->a.teacher_params,
                  "Teacher kwarg by the reference's name, k=v (v as JSON; repeatable)");
  run->add_option("--allow_expert_knowledge", rn->a.expert_knowledge, "none | low | high");
  run->add_option("--nb_env_steps", rn->a.nb_env_steps, "Training env steps, in millions");
  run->add_option("--steps", rn->a.steps, "Training env steps (plain) instead of --nb_env_steps")
      ->check(CLI::Range(1L, static_cast<long>(train::kTmaMaxMillions * 1e6)))
      ->excludes("--nb_env_steps")
      ->default_str("");
  run->add_option("--test_set", rn->a.test_set,
                  "Test set of data/teachmyagent (e.g. parametric_stumps_test_set); default: "
                  "the grid (Stump Tracks) or 100 fixed uniform tasks");
  run->add_option("--nb_test_episodes,--nb_test_episode", rn->a.nb_test_episodes,
                  "Size of the default test set");
  run->add_option("--seed", rn->a.seed, "Seed of the student, teacher and shuffling")->check(kSeed);
  run->add_option("--keep_periodical_task_samples", rn->a.keep_periodical_task_samples,
                  "Env steps between 100-task curriculum snapshots (0: none)");
  run->add_flag("--shuffle_dimensions", rn->a.shuffle_dimensions, "Rugged difficulty (4x4)");
  run->add_flag("--scale_reward", rn->a.scale_reward, "The teacher sees returns scaled to [0, 1]");
  run->add_option("--test_every,--steps_per_ep", rn->a.test_every, "Env steps between evaluations");
  run->add_option("--reset_frequency", rn->a.reset_frequency,
                  "Env steps between student resets (0: never; criterion 3: 7000000)");
  run->add_option("--min_stump_h", rn->a.min_stump_h, "Stump Tracks: lowest mean stump height");
  run->add_option("--max_stump_h", rn->a.max_stump_h, "Stump Tracks: highest mean stump height");
  run->add_option("--max_obstacle_spacing", rn->a.max_obstacle_spacing,
                  "Stump Tracks: largest spacing");
  run->add_option("--lr", rn->a.lr, "Student learning rate (default: the preset's)");
  run->add_option("--hp", rn->a.hp, "Student hyperparameter override name=value (repeatable)");
  run->add_option("--out", rn->a.out,
                  "Run folder (default tma_runs/<exp_name>/<exp_name>_s<seed>)");
  run->add_flag("--resume", rn->a.resume, "Continue the run in --out from its last checkpoint");
  run->add_flag("--overwrite", rn->a.overwrite, "Replace the run already in --out");
  run->add_flag("--no-progress", rn->no_progress, "No progress bar");
  add_distributed_flags(run, rn->dist);
  run->callback([rn] {
    train::TmaRunArguments a = rn->a;
    a.progress_bar = !rn->no_progress;
    a.env_options = rn->env_flags.given_text();
    a.commit = source_commit();
    // Ctrl-C or a scheduler's SIGTERM ends the run at its next report instead of killing it.
    a.stop = stop_on({SIGINT, SIGTERM});
    train::TmaRun run;
    const int rank = run_as_rank(rn->dist, [&](std::shared_ptr<learn::GradSync> sync) {
      a.sync = std::move(sync);
      run = train::run_tma(a);
      a.sync.reset();  // the ranks' group ends with this call
      return run.parameter_hash;
    });
    const std::filesystem::path& out = run.out;
    if (run.stopped && rank > 0) throw Stopped{};
    if (rank > 0) return;                           // rank 0 reports the run
    const nlohmann::ordered_json& r = run.summary;  // summary.json's figures
    const auto number = [&](const char* key) { return r.at(key).get<double>(); };
    std::printf(
        "%s: %.0f env steps, %.0f episodes, %.0f evaluations, %.1f s, %.0f env steps/s, %.1f "
        "gradient steps/s, teacher %.2f%% of the time, %.0f%% mastered\n",
        out.string().c_str(), number("env_steps"), number("episodes"), number("evaluations"),
        number("wall_s"), number("env_steps_per_s"), number("gradient_steps_per_s"),
        100 * number("teacher_share"), number("pct_mastered"));
    if (run.stopped) {
      std::printf(
          "stopped by a signal at %.0f env steps; --resume continues from its checkpoint there: "
          "cradle tma run ... --out %s --resume\n",
          number("checkpoint_env_steps"), out.string().c_str());
      throw Stopped{};  // exit 130: `tma campaign` must not count the seed as finished
    }
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

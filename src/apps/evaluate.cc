// `cradle evaluate --config FILE [--episodes 10] [--duration 1000] [--render | --no-render]
// [--seed S] [--video-format mp4|avi]`: the reference's evaluation.py, with scores. Videos are
// written with --render only (the reference films by default): a filmed frame costs 0.15-0.35 s.
// `cradle evaluate --run DIR [--checkpoint final] [--episodes N] [--seed S] [--render]`: the
// trained policy of a run of any family (train/run_policy.h), played on a fresh env of its id.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "apps/cli_checks.h"
#include "apps/commands.h"
#include "apps/env_film.h"
#include "core/config.h"
#include "core/error.h"
#include "envs/registry.h"
#include "eval/video.h"
#include "train/episodes.h"
#include "train/evaluation.h"
#include "train/run_policy.h"
#include "train/trainer.h"

namespace cradle::apps {
namespace {

namespace fs = std::filesystem;

struct RunEvaluation {
  std::string run;
  std::string checkpoint = "final";
  int episodes = 10;
  int max_steps = 0;  // 0: each episode runs until the env ends it
  std::optional<std::uint64_t> seed;
  bool render = false;
  bool sampled = false;
  std::string video_extension = ".mp4";
};

// `cradle evaluate --run DIR`: the run's policy on a fresh env of its id, one line per episode
// as it finishes, then DIR/evaluation_<checkpoint>.json (and videos with --render).
void evaluate_run(const RunEvaluation& o) {
  const fs::path dir = o.run;
  const train::RunPolicy policy = train::load_run_policy(dir, o.checkpoint, o.sampled);
  const train::RunInfo& run = policy.run();
  if (run.env.empty()) {
    throw UserError("--run " + o.run +
                    " trained a BabyBench config: evaluate it with --config FILE (the config it "
                    "trained) --policy " +
                    policy.checkpoint().string());
  }
  // By default the seeds of the run's own evaluation (evaluation.json): run seed + 1000 + k.
  const std::uint64_t first = o.seed ? *o.seed : run.seed + 1000;
  std::unique_ptr<envs::Env> env = envs::make_env(run.env, first);
  std::unique_ptr<EnvFilm> film;
  std::optional<eval::VideoWriter> video;
  const std::string name = policy.checkpoint_name();
  if (o.render) {
    film = std::make_unique<EnvFilm>(*env);
    std::error_code ec;
    fs::create_directories(dir / "videos", ec);
    if (ec) throw UserError("cannot create '" + (dir / "videos").string() + "': " + ec.message());
  }
  std::printf("%s, %s policy of %s (%ld steps), %s actions\n", run.env.c_str(),
              run.algorithm.c_str(), name.c_str(), policy.steps(), o.sampled ? "sampled" : "mean");
  std::printf("%7s %20s %12s %7s %7s %7s\n", "episode", "seed", "return", "length", "success",
              "score");
  std::vector<train::EpisodeOutcome> episodes;
  const train::EpisodePolicy act = policy.episode_policy();
  for (int k = 0; k < o.episodes; ++k) {
    const std::uint64_t seed = first + static_cast<std::uint64_t>(k);
    if (film) {
      video.emplace(dir / "videos" / (name + "_episode_" + std::to_string(k) + o.video_extension),
                    film->width(), film->height(), film->fps());
    }
    train::EpisodeStepFn on_step;
    if (film)
      on_step = [&](int, const envs::Env&, const envs::StepResult&) { video->write(film->draw()); };
    const train::EpisodeOutcome e =
        train::run_episodes(*env, act, std::span(&seed, 1), o.max_steps, on_step).front();
    if (video) video->close();
    episodes.push_back(e);
    const std::string score = std::isfinite(e.score) ? std::to_string(e.score) : "-";
    std::printf("%7d %20llu %12.4f %7d %7s %7s\n", k, static_cast<unsigned long long>(seed),
                e.episode_return, e.length, e.success ? "yes" : "no", score.c_str());
  }
  env->close();
  nlohmann::ordered_json report = {{"env", run.env},
                                   {"algorithm", run.algorithm},
                                   {"checkpoint", name},
                                   {"steps", policy.steps()},
                                   {"policy_actions", o.sampled ? "sampled" : "mean"}};
  report.update(train::episodes_json(episodes));
  std::printf("mean return %.4f +- %.4f, mean length %.1f, success rate %.2f\n",
              report["mean_return"].get<double>(), report["std_return"].get<double>(),
              report["mean_length"].get<double>(), report["success_rate"].get<double>());
  const fs::path file = dir / ("evaluation_" + name + ".json");
  std::ofstream out(file, std::ios::trunc);
  out << report.dump(2) << "\n";
  if (!out.flush()) throw UserError("cannot write '" + file.string() + "'");
  std::printf("wrote %s%s\n", file.string().c_str(),
              o.render ? (" and " + (dir / "videos").string() + "/" + name + "_episode_<i>" +
                          o.video_extension)
                             .c_str()
                       : "");
}

}  // namespace

void register_evaluate(CLI::App& app) {
  struct Options {
    std::string config;
    std::string save_dir;
    int episodes = 10;
    int duration = 1000;
    bool render = false;
    std::uint64_t seed = 0;
    std::string format = "mp4";
    std::string policy;
    bool stochastic = false;
    std::string run;
    std::string checkpoint = "final";
  };
  auto opts = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "evaluate",
      "Score the training log, then run evaluation episodes (random or trained policy) and write "
      "trajectories, evaluation.json, plots and, with --render, videos under save_dir.\n"
      "Scores: self-touch = (|geoms touched by right hand| + |by left hand|) / 68, unions over "
      "the last <= 10,000 logged episodes; hand regard = mean over the 4 eye-hand pairs of the "
      "fraction of steps in view (reference), and the mean over the eyes of the fraction with "
      "either hand in view (competition site).\n"
      "With --run DIR instead of --config: the trained policy of a run by env id (any family) on a "
      "fresh env of its id; writes DIR/evaluation_<checkpoint>.json and, with --render, "
      "DIR/videos/.");
  CLI::Option* config_option = cmd->add_option("--config", opts->config, "BabyBench YAML config");
  CLI::Option* run_option = cmd->add_option(
      "--run", opts->run,
      "Instead of --config: the folder of a run trained by env id (cradle train --env ID, "
      "cradle.train(env=...)); plays its trained policy on a fresh env of the id and writes "
      "DIR/evaluation_<checkpoint>.json");
  config_option->excludes(run_option);
  cmd->add_option("--checkpoint", opts->checkpoint,
                  "With --run: final, latest, step_<n> or a .ckpt file (default: final)")
      ->needs(run_option);
  CLI::Option* save_dir_option = cmd->add_option("--out,--save-dir", opts->save_dir,
                                                 "Output folder (default: the config's save_dir)");
  save_dir_option->excludes(run_option);
  cmd->add_option("--episodes", opts->episodes, "Evaluation episodes")
      ->check(CLI::Range(1, 1000000));
  CLI::Option* duration_option =
      cmd->add_option("--duration", opts->duration,
                      "Env steps per episode (with --run: at most this many; default: until the "
                      "env ends the episode)")
          ->check(CLI::Range(1, 100000000));
  cmd->add_flag("--render,!--no-render", opts->render,
                "Film every episode into videos/ (0.15-0.35 s a frame: minutes per episode); the "
                "reference's evaluation.py films by default, --render does as it does. Default: "
                "--no-render, no videos");
  CLI::Option* seed_option =
      cmd->add_option("--seed", opts->seed,
                      "Seed: episode i resets with seed + i (with --run, default: the run's seed + "
                      "1000, the seeds of its own evaluation.json)")
          ->check(kSeed);
  CLI::Option* policy_option =
      cmd->add_option("--policy", opts->policy,
                      "Checkpoint of a trained policy (cradle train); default: random actions");
  policy_option->excludes(run_option);
  cmd->add_flag("--stochastic", opts->stochastic,
                "Sample the policy's actions (SB3's predict() default) instead of its mean action "
                "(with --policy or --run)");
  cmd->add_option("--video-format", opts->format, "Video container")
      ->check(CLI::IsMember({"mp4", "avi"}));
  cmd->callback([opts, run_option, config_option, policy_option, seed_option, duration_option] {
    if (run_option->count() == 0 && config_option->count() == 0) {
      throw UserError(
          "evaluate needs --config FILE (a BabyBench config) or --run DIR (a run "
          "trained by env id)");
    }
    if (opts->stochastic && run_option->count() == 0 && policy_option->count() == 0) {
      throw UserError(
          "--stochastic requires --policy CHECKPOINT or --run DIR (a trained policy to "
          "sample)");
    }
    if (run_option->count() > 0) {
      // Line-buffered: each episode's line shows as it finishes.
      std::setvbuf(stdout, nullptr, _IOLBF, BUFSIZ);
      evaluate_run({.run = opts->run,
                    .checkpoint = opts->checkpoint,
                    .episodes = opts->episodes,
                    .max_steps = duration_option->count() > 0 ? opts->duration : 0,
                    .seed = seed_option->count() > 0 ? std::optional(opts->seed) : std::nullopt,
                    .render = opts->render,
                    .sampled = opts->stochastic,
                    .video_extension = "." + opts->format});
      return;
    }
    // One line per finished episode (its score and seconds): shown as it comes, also when stdout
    // goes to a file or a pipe.
    std::setvbuf(stdout, nullptr, _IOLBF, BUFSIZ);
    Config config = load_config(opts->config);
    if (!opts->save_dir.empty()) config.save_dir = opts->save_dir;
    train::EvaluationOptions options{.episodes = opts->episodes,
                                     .duration = opts->duration,
                                     .render = opts->render,
                                     .seed = opts->seed,
                                     .video_extension = "." + opts->format,
                                     .policy_actions = opts->policy.empty() ? "random"
                                                       : opts->stochastic   ? "sampled"
                                                                            : "mean"};
    const std::string behavior(behavior_name(config.behavior));
    const train::Policy policy =
        opts->policy.empty() ? nullptr : train::load_policy(config, opts->policy, opts->stochastic);
    const train::EvaluationReport r = train::evaluate(config, options, policy);
    if (r.training_score) {
      std::printf("training log: %d entries, score %.4f\n", r.training_episodes, *r.training_score);
    } else {
      std::printf("training log: %s\n",
                  r.training_episodes ? "no score for behavior none" : "none found");
    }
    if (config.behavior != Behavior::kNone) {
      std::printf("evaluation (%s, %d episodes x %d steps, %s actions): %.4f +- %.4f\n",
                  behavior.c_str(), opts->episodes, opts->duration, options.policy_actions.c_str(),
                  r.mean, r.std);
    }
    if (config.behavior == Behavior::kHandRegard) {
      double either = 0;
      for (const auto& e : r.episodes) either += e.hand_regard ? e.hand_regard->either : 0;
      std::printf("hand regard, either hand in view of each eye: %.4f\n",
                  either / static_cast<double>(r.episodes.size()));
    }
    std::printf("wrote %s/{evaluation.json, trajectories/, %splots/}\n", config.save_dir.c_str(),
                opts->render ? "videos/, " : "");
  });
}

}  // namespace cradle::apps

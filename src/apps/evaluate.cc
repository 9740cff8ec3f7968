// `cradle evaluate --config FILE [--episodes 10] [--duration 1000] [--render | --no-render]
// [--seed S] [--video-format mp4|avi]`: the reference's evaluation.py, with scores. Videos are
// written with --render only (the reference films by default): a filmed frame costs 0.15-0.35 s.
#include <cstdio>
#include <memory>
#include <string>

#include "apps/cli_checks.h"
#include "apps/commands.h"
#include "core/config.h"
#include "train/evaluation.h"
#include "train/trainer.h"

namespace cradle::apps {

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
  };
  auto opts = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "evaluate",
      "Score the training log, then run evaluation episodes (random or trained policy) and write "
      "trajectories, evaluation.json, plots and, with --render, videos under save_dir.\n"
      "Scores: self-touch = (|geoms touched by right hand| + |by left hand|) / 68, unions over "
      "the last <= 10,000 logged episodes; hand regard = mean over the 4 eye-hand pairs of the "
      "fraction of steps in view (reference), and the mean over the eyes of the fraction with "
      "either hand in view (competition site).");
  cmd->add_option("--config", opts->config, "BabyBench YAML config")->required();
  cmd->add_option("--save-dir", opts->save_dir, "Output folder (default: the config's save_dir)");
  cmd->add_option("--episodes", opts->episodes, "Evaluation episodes")
      ->check(CLI::Range(1, 1000000));
  cmd->add_option("--duration", opts->duration, "Env steps per episode")
      ->check(CLI::Range(1, 100000000));
  cmd->add_flag("--render,!--no-render", opts->render,
                "Film every episode into videos/ (0.15-0.35 s a frame: minutes per episode); the "
                "reference's evaluation.py films by default, --render does as it does. Default: "
                "--no-render, no videos");
  cmd->add_option("--seed", opts->seed, "Seed: episode i resets with seed + i")->check(kSeed);
  CLI::Option* policy_option =
      cmd->add_option("--policy", opts->policy,
                      "Checkpoint of a trained policy (cradle train); default: random actions");
  cmd->add_flag("--stochastic", opts->stochastic,
                "Sample the policy's actions (SB3's predict() default) instead of its mean action")
      ->needs(policy_option);
  cmd->add_option("--video-format", opts->format, "Video container")
      ->check(CLI::IsMember({"mp4", "avi"}));
  cmd->callback([opts] {
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

// `cradle train --config FILE --algo ppo --intrinsic NAME[,NAME...] --steps N --envs K --seed S
// [--resume] [--randomize-start]`: trains a policy, checkpoints it and evaluates it. `--env ID`
// instead of --config trains any registered env (`cradle envs`; e.g. with --task-space and
// --teacher); a BabyBench id trains its config.
#include <csignal>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "apps/cli_checks.h"
#include "apps/commands.h"
#include "apps/distributed_flags.h"
#include "apps/interrupt.h"
#include "core/config.h"
#include "core/error.h"
#include "envs/registry.h"
#include "learn/hyperparams.h"
#include "learn/registry.h"
#include "train/env_vector.h"
#include "train/trainer.h"

namespace cradle::apps {
namespace {

// What a finished (or stopped) `cradle train` prints about its files and scores.
void report_files(const Config& config, const train::TrainOptions& train,
                  const train::TrainResult& r) {
  std::printf("checkpoint: %s\n", r.checkpoint.c_str());
  if (r.training_score) std::printf("training-log score: %.4f\n", *r.training_score);
  if (r.evaluation) {
    std::printf("evaluation of the trained policy (%zu episodes): %.4f +- %.4f\n",
                r.evaluation->episodes.size(), r.evaluation->mean, r.evaluation->std);
  }
  if (r.random_evaluation) {
    std::printf(
        "evaluation of the random policy  (%zu episodes): %.4f +- %.4f  (trained / "
        "random = %.2f)\n",
        r.random_evaluation->episodes.size(), r.random_evaluation->mean, r.random_evaluation->std,
        r.evaluation ? r.evaluation->mean / r.random_evaluation->mean : 0.0);
  }
  if (!r.episodes.empty()) {
    const nlohmann::ordered_json e = train::episodes_json(r.episodes);
    std::printf(
        "evaluation of the trained policy (%zu episodes): return %.4g +- %.4g, length %.0f, "
        "success %.0f%% (%s/evaluation.json)\n",
        r.episodes.size(), e["mean_return"].get<double>(), e["std_return"].get<double>(),
        e["mean_length"].get<double>(), 100 * e["success_rate"].get<double>(),
        config.save_dir.c_str());
  }
  if (!train.env.empty()) {
    std::printf("logs: %s/logs/progress.csv%s; plots: %s/plots/\n", config.save_dir.c_str(),
                train.task_space.empty() && train.teacher.empty() ? "" : ", teacher.jsonl",
                config.save_dir.c_str());
    return;
  }
  std::printf(
      "logs: %s/logs/{training.jsonl, progress.csv}; plots: %s/plots/; videos: %s/videos/\n",
      config.save_dir.c_str(), config.save_dir.c_str(), config.save_dir.c_str());
}

}  // namespace

void register_train(CLI::App& app) {
  struct Options {
    std::string config;
    std::string save_dir;
    cradle::train::TrainOptions train;
    std::vector<std::string> hp;
    bool no_eval = false;
    DistributedFlags dist;
  };
  auto opts = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("train", "Train a policy with intrinsic motivation");
  cmd->add_option("--config", opts->config, "BabyBench YAML config (or --env)");
  cmd->add_option("--env", opts->train.env,
                  "An env id instead (`cradle envs`: babybench/..., mimo/..., tma/..., sami/...)");
  cmd->add_option("--out,--save-dir", opts->save_dir,
                  "Output folder (default: the config's save_dir)");
  cmd->add_option("--algo", opts->train.algorithm, "Learning algorithm")
      ->check(CLI::IsMember(learn::algorithm_names()))
      ->capture_default_str();
  cmd->add_option("--intrinsic", opts->train.intrinsic,
                  "Intrinsic rewards, name[:weight],... ('' for none)");
  cmd->add_option("--steps", opts->train.steps, "Env steps in total")
      ->check(CLI::Range(1L, 100000000000L));
  cmd->add_option("--envs", opts->train.envs, "Parallel envs")->check(CLI::Range(1, 1024));
  cmd->add_option("--threads", opts->train.threads, "Worker threads (0: one per env, <= cores)")
      ->check(CLI::Range(0, 1024));
  cmd->add_option("--procs", opts->train.procs,
                  "Run the envs in N worker processes (--envs a multiple of N): envs that render "
                  "draw in parallel (default: threads)")
      ->check(CLI::Range(1, 1024))
      ->default_str("");
  cmd->add_option("--async-batch", opts->train.async_batch,
                  "PPO/A2C: collect asynchronously in batches of the first K envs (K < --envs; "
                  "default: lock-step)")
      ->check(CLI::Range(1, 1024))
      ->default_str("");
  cmd->add_option(
         "--update-threads", opts->train.update_threads,
         "LibTorch threads for gradient updates (0: every core for image policies, 1 otherwise)")
      ->check(CLI::Range(0, 1024));
  cmd->add_option("--seed", opts->train.seed, "Seed of everything")->check(kSeed);
  cmd->add_flag("!--no-progress", opts->train.progress_bar, "No progress bar");
  cmd->add_flag("--resume", opts->train.resume, "Continue from <save_dir>/checkpoints/latest.ckpt");
  cmd->add_flag("--overwrite", opts->train.overwrite,
                "Replace the run already in the folder (its checkpoints, logs and plots)");
  cmd->add_flag("--randomize-start", opts->train.randomize_start,
                "Random start postures within joint limits");
  cmd->add_option("--checkpoint-every", opts->train.checkpoint_every,
                  "Env steps between checkpoints")
      ->check(CLI::Range(1L, 100000000000L));
  cmd->add_option("--reset-every", opts->train.reset_every,
                  "Env steps between fresh learners (networks, optimiser, buffer; 0: never)")
      ->check(CLI::Range(0L, 100000000000L));
  cmd->add_option("--hp", opts->hp, "Hyperparameter override name=value (repeatable)");
  cmd->add_option("--task-space", opts->train.task_space,
                  "Curriculum: task-space YAML whose teacher sets the reset options");
  cmd->add_option("--teacher", opts->train.teacher,
                  "Curriculum teacher (overrides the file's); without --task-space it sets every "
                  "task parameter the env declares (`cradle envs`)");
  cmd->add_option("--eval-episodes", opts->train.eval_episodes, "Evaluation episodes at the end")
      ->check(CLI::Range(0, 100000));
  cmd->add_flag("--compare-random", opts->train.compare_random,
                "Also evaluate the random policy (same seeds) and print both scores");
  cmd->add_flag(
      "--no-eval-video", [opts](std::int64_t) { opts->train.eval_render = false; },
      "Evaluate without writing videos");
  // Data-parallel training (docs/distributed.md).
  add_distributed_flags(cmd, opts->dist);
  cmd->callback([opts, cmd] {
    // --resume continues the checkpoint's algorithm; an --algo that contradicts it is refused.
    if (opts->train.resume && cmd->get_option("--algo")->count() == 0) {
      opts->train.algorithm.clear();
    }
    // A BabyBench config or a MIMo sample env (its run folder: --save-dir, else results/<env>).
    Config config;
    if (!opts->train.env.empty() && !opts->config.empty())
      throw UserError("--config and --env " + opts->train.env + ": give one of them");
    // A BabyBench id trains its config, with everything a config run has.
    bool babybench_id = false;
    if (!opts->train.env.empty()) {
      if (const std::optional<Config> c = train::babybench_config(opts->train.env)) {
        config = *c;
        opts->train.env.clear();
        babybench_id = true;
      }
    }
    if (opts->train.env.empty()) {
      if (opts->config.empty() && !babybench_id)
        throw UserError("give --config FILE.yml (BabyBench) or --env ID (`cradle envs`)");
      if (!babybench_id) config = load_config(opts->config);
    } else {
      for (const char* flag : {"--randomize-start", "--compare-random", "--no-eval-video"}) {
        if (cmd->get_option(flag)->count() > 0)
          throw UserError(std::string(flag) + " is for BabyBench configs, not --env " +
                          opts->train.env);
      }
      // The env's own reward unless intrinsic rewards are asked for.
      if (cmd->get_option("--intrinsic")->count() == 0) opts->train.intrinsic.clear();
      config.save_dir = "results/" + train::registered_env_id(opts->train.env);
    }
    if (!opts->save_dir.empty()) config.save_dir = opts->save_dir;
    opts->train.hyperparameters = learn::parse_hyperparameter_flags(opts->hp);
    // Ctrl-C, or SIGTERM from srun, `cradle launch` or a scheduler's time limit, ends the run at
    // its next update with a checkpoint.
    opts->train.stop = stop_on({SIGINT, SIGTERM});
    train::TrainResult r;
    const int rank = run_as_rank(opts->dist, [&](std::shared_ptr<learn::GradSync> sync) {
      opts->train.sync = std::move(sync);
      r = train::train(config, opts->train);
      opts->train.sync.reset();  // the ranks' group ends with this call
      return r.parameter_hash;
    });
    const bool stopped = opts->train.stop->load();
    std::printf("trained %ld env steps in %.0f s (%.0f steps/s)%s\n", r.steps, r.seconds,
                r.steps_per_second, stopped ? " — interrupted" : "");
    // Rank 0 reports the run's files; a stopped run then exits 130, not 0.
    if (rank == 0) report_files(config, opts->train, r);
    if (stopped) throw Stopped{};
  });
}

}  // namespace cradle::apps

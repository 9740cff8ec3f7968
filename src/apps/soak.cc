// `cradle soak --config FILE | --env ID [--steps N] [--envs N] [--threads T | --procs P]
// [--eval-every N] ...`: the long-running vision soak. Random actions drive a vector of envs on a
// thread pool (or in worker processes) for N env steps; every --eval-every steps an evaluation env
// (with its video renderer, for a BabyBench config) is built, run and destroyed on the main thread
// while the vector's contexts live (the train -> evaluation transition that crashed), and the run
// ends with one more evaluation. It prints progress, steps/s and the resident memory (of each
// worker process too), and exits 0 only when everything finished.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "apps/cli_checks.h"
#include "apps/commands.h"
#include "core/config.h"
#include "core/error.h"
#include "core/folders.h"
#include "core/rng.h"
#include "envs/registry.h"
#include "learn/proc_vector_env.h"
#include "train/babybench_vector.h"
#include "train/env_vector.h"
#include "train/episodes.h"
#include "train/evaluation.h"

namespace cradle::apps {
namespace {

// Resident and peak resident memory of a process, MB (/proc/<pid>/status; 0 when it is gone).
std::pair<double, double> resident_mb(const std::string& pid = "self") {
  std::ifstream status("/proc/" + pid + "/status");
  std::string line;
  double rss = 0, peak = 0;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) rss = std::stod(line.substr(6)) / 1024;
    if (line.rfind("VmHWM:", 0) == 0) peak = std::stod(line.substr(6)) / 1024;
  }
  return {rss, peak};
}

}  // namespace

void register_soak(CLI::App& app) {
  struct Options {
    std::string config;
    std::string env;
    std::string save_dir;
    long steps = 500000;
    int envs = 2;
    int threads = 0;
    int procs = 0;
    long eval_every = 100000;
    int eval_episodes = 1;
    int eval_duration = 1000;
    bool no_video = false;
    std::uint64_t seed = 0;
  };
  auto opts = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "soak", "Vision soak: random actions on a vector of envs, evaluations with video between");
  CLI::Option* config_flag = cmd->add_option("--config", opts->config, "BabyBench YAML config");
  CLI::Option* env_flag =
      cmd->add_option("--env", opts->env,
                      "An env id instead of a config (`cradle envs`), e.g. mimo/bench: its "
                      "evaluations run random episodes without video");
  config_flag->excludes(env_flag);
  env_flag->excludes(config_flag);
  cmd->add_option("--out,--save-dir", opts->save_dir,
                  "Output folder (default: the config's save_dir; with --env, runs/soak)");
  cmd->add_option("--steps", opts->steps, "Env steps in total")
      ->check(CLI::Range(1L, 100000000000L));
  cmd->add_option("--envs", opts->envs, "Parallel envs")->check(CLI::Range(1, 1024));
  cmd->add_option("--threads", opts->threads, "Worker threads (0: one per env, <= cores)")
      ->check(CLI::Range(0, 1024));
  cmd->add_option("--procs", opts->procs,
                  "Run the envs in N worker processes (--envs a multiple of N) instead of threads "
                  "(default: threads)")
      ->check(CLI::Range(1, 1024))
      ->default_str("");  // 0 stands for threads
  cmd->add_option("--eval-every", opts->eval_every,
                  "Env steps between evaluations run beside the live vector")
      ->check(CLI::Range(1L, 100000000000L));
  cmd->add_option("--eval-episodes", opts->eval_episodes, "Episodes per evaluation")
      ->check(CLI::Range(1, 1000));
  cmd->add_option("--eval-duration", opts->eval_duration, "Env steps per evaluation episode")
      ->check(CLI::Range(1, 1000000));
  cmd->add_flag("--no-eval-video", opts->no_video, "Evaluate without videos");
  cmd->add_option("--seed", opts->seed, "Seed of the envs and the random actions")->check(kSeed);
  cmd->callback([opts] {
    using Clock = std::chrono::steady_clock;
    if (opts->config.empty() == opts->env.empty())
      throw UserError("soak: give a BabyBench config (--config FILE) or an env id (--env ID)");
    const bool by_id = !opts->env.empty();
    // An unknown id is refused before anything runs.
    const std::string env_id = by_id ? envs::env_spec(opts->env).id : "";
    if (by_id && envs::env_spec(env_id).family == "babybench")
      throw UserError("soak: --env " + opts->env + " is a BabyBench config: give it as --config");
    Config config = by_id ? default_config() : load_config(opts->config);
    if (by_id) config.save_dir = "runs/soak";
    if (!opts->save_dir.empty()) config.save_dir = opts->save_dir;
    if (opts->procs > 0) train::check_procs_split(opts->envs, opts->procs, "soak: ");
    const std::filesystem::path dir = config.save_dir;
    make_folder(dir, "soak: cannot create the output folder");
    // The progress lines as a table, for the memory curve: soak.csv in the output folder.
    std::ofstream table(dir / "soak.csv");
    if (!table) throw UserError("soak: cannot write '" + (dir / "soak.csv").string() + "'");
    int evaluations = 0;
    // An evaluation (own env, renderer and video) on this thread, in its own folder.
    auto evaluate_config = [&](const char* when) {
      Config ec = config;
      ec.save_dir = (dir / ("soak_eval_" + std::to_string(evaluations++))).string();
      const train::EvaluationOptions eo{.episodes = opts->eval_episodes,
                                        .duration = opts->eval_duration,
                                        .render = !opts->no_video,
                                        .seed = opts->seed + 1000,
                                        .quiet = true};
      const Clock::time_point t = Clock::now();
      const train::EvaluationReport report = train::evaluate(ec, eo);
      std::printf("evaluation %d (%s): %zu episodes, mean score %.4f, %.1f s\n", evaluations, when,
                  report.episodes.size(), report.mean,
                  std::chrono::duration<double>(Clock::now() - t).count());
      std::fflush(stdout);
    };
    // An env id's evaluation: a fresh env of the id (its own renderers, if it has eyes) plays
    // random episodes of at most --eval-duration steps.
    auto evaluate_id = [&](const char* when) {
      ++evaluations;
      const Clock::time_point t = Clock::now();
      std::unique_ptr<envs::Env> env = envs::make_env(env_id, opts->seed + 1000);
      const Box& space = env->action_space();
      Rng rng(opts->seed + 2000 + static_cast<std::uint64_t>(evaluations));
      const train::EpisodePolicy random{
          .act = [&](const envs::ObservationBuffers&, std::span<double> action) {
            space.sample(rng, action);
          }};
      std::vector<std::uint64_t> seeds;
      for (int e = 0; e < opts->eval_episodes; ++e) seeds.push_back(opts->seed + 1000 + e);
      const std::vector<train::EpisodeOutcome> episodes =
          train::run_episodes(*env, random, seeds, opts->eval_duration);
      double total = 0;
      for (const train::EpisodeOutcome& e : episodes) total += e.episode_return;
      std::printf("evaluation %d (%s): %zu episodes, mean return %.4f, %.1f s\n", evaluations, when,
                  episodes.size(), total / static_cast<double>(episodes.size()),
                  std::chrono::duration<double>(Clock::now() - t).count());
      std::fflush(stdout);
    };
    auto evaluate = [&](const char* when) { by_id ? evaluate_id(when) : evaluate_config(when); };

    const Clock::time_point start = Clock::now();
    long steps = 0;
    Clock::duration stepping{};  // inside the vector's step calls
    {
      std::unique_ptr<learn::VecEnv> vec;
      if (by_id) {
        vec = train::make_env_training(env_id, opts->envs, opts->threads, opts->seed, nullptr, 0,
                                       {}, opts->procs)
                  .vec;
      } else if (opts->procs > 0) {
        vec = train::make_babybench_proc_vec_env(config, opts->envs, opts->procs,
                                                 /*training=*/false, opts->seed);
      } else {
        vec = train::make_babybench_vec_env(config, opts->envs, opts->threads,
                                            /*training=*/false, opts->seed);
      }
      const int n = vec->num_envs();
      const auto* procs = dynamic_cast<const learn::ProcVecEnv*>(vec.get());
      table << "steps,seconds,steps_per_s,rss_mb,peak_rss_mb";
      for (int w = 0; procs && w < procs->procs(); ++w) table << ",worker_" << w << "_rss_mb";
      table << "\n";
      const Box& space = vec->action_space();
      std::vector<double> actions(static_cast<size_t>(n) * space.size());
      Rng rng(opts->seed + 1);
      vec->reset(opts->seed);
      long next_eval = opts->eval_every;
      long next_print = 10000;
      while (steps < opts->steps) {
        space.sample(rng, actions);
        const Clock::time_point before = Clock::now();
        vec->step(actions);
        stepping += Clock::now() - before;
        steps += n;
        if (steps >= next_print) {
          const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
          const auto [rss, peak] = resident_mb();
          std::printf("%ld steps, %.0f steps/s, RSS %.0f MB (peak %.0f MB)", steps, steps / seconds,
                      rss, peak);
          table << steps << "," << seconds << "," << steps / seconds << "," << rss << "," << peak;
          if (procs) {
            std::printf(", workers");
            for (const pid_t pid : procs->worker_pids()) {
              const double worker_rss = resident_mb(std::to_string(pid)).first;
              std::printf(" %.0f", worker_rss);
              table << "," << worker_rss;
            }
            std::printf(" MB");
          }
          std::printf("\n");
          table << "\n";
          table.flush();
          std::fflush(stdout);
          next_print += 10000;
        }
        // The transition that crashed: an evaluation while the vector's contexts live, then
        // fresh episodes on the pool as a new learn() call starts them.
        if (steps >= next_eval && steps < opts->steps) {
          evaluate("beside the vector");
          vec->reset(opts->seed + steps);
          next_eval += opts->eval_every;
        }
      }
    }
    evaluate("after the vector");
    const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
    std::printf(
        "soak finished: %ld env steps on %d envs%s, %d evaluations, %.0f s, peak RSS %.0f MB; %.1f "
        "env steps/s inside the vector's steps\n",
        steps, opts->envs,
        opts->procs > 0 ? (" in " + std::to_string(opts->procs) + " processes").c_str() : "",
        evaluations, seconds, resident_mb().second,
        steps / std::max(std::chrono::duration<double>(stepping).count(), 1e-9));
  });
}

}  // namespace cradle::apps

// `cradle bench --config FILE | --env NAME [--steps N] [--seed S] [--json]`: env steps/s with a
// random policy, per-module time per step, and bare mj_step on the same compiled model, measured
// in one run. --env takes a MIMo sample env (MIMoReach-v0, ...; "all" runs every one).
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "apps/cli_checks.h"
#include "apps/commands.h"
#include "core/config.h"
#include "core/error.h"
#include "core/rng.h"
#include "envs/babybench.h"
#include "envs/mimo/sample_env.h"

namespace cradle::apps {
namespace {

struct BenchResult {
  double env_steps_per_s = 0, bare_steps_per_s = 0, ratio = 0, realtime_factor = 0;
  envs::Profile per_step;  // seconds per env step
  int steps = 0, frame_skip = 1;
};

// Times `steps` env steps with random actions, then frame_skip x steps bare mj_steps from
// `start` on the same model.
template <typename EnvT>
BenchResult time_env(EnvT& env, const mjModel* m, ActuationModel actuation, int frame_skip,
                     const sim::State& start, int steps, std::uint64_t seed) {
  using Clock = std::chrono::steady_clock;
  env.reset(seed);
  env.clear_profile();

  // Env: random actions within the action bounds; resets are not timed.
  const Box& space = env.action_space();
  std::vector<double> action(space.size());
  Rng rng(seed + 1);
  double env_seconds = 0;
  for (int i = 0; i < steps; ++i) {
    for (size_t k = 0; k < action.size(); ++k) action[k] = rng.uniform(space.low[k], space.high[k]);
    const Clock::time_point t = Clock::now();
    const envs::StepResult r = env.step(action);
    env_seconds += std::chrono::duration<double>(Clock::now() - t).count();
    if (r.terminated || r.truncated) env.reset();
  }

  // Bare physics: the same model and start state, random controls, frame_skip steps per action.
  sim::Sim bare(m, actuation, 1);
  bare.restore(start);
  mjData* d = bare.data();
  const int substeps = steps * frame_skip;
  const Clock::time_point t = Clock::now();
  for (int i = 0; i < substeps; ++i) {
    if (i % frame_skip == 0) {
      for (int u = 0; u < m->nu; ++u) {
        const bool limited = m->actuator_ctrllimited[u];
        d->ctrl[u] =
            limited ? rng.uniform(m->actuator_ctrlrange[2 * u], m->actuator_ctrlrange[2 * u + 1])
                    : 0;
      }
    }
    mj_step(m, d);
  }
  const double bare_seconds = std::chrono::duration<double>(Clock::now() - t).count();

  BenchResult r;
  r.steps = steps;
  r.frame_skip = frame_skip;
  r.env_steps_per_s = steps / env_seconds;
  r.bare_steps_per_s = substeps / bare_seconds;
  r.ratio = (env_seconds / steps) / (frame_skip * bare_seconds / substeps);
  r.realtime_factor = r.env_steps_per_s * frame_skip * m->opt.timestep;
  const envs::Profile& p = env.profile();
  const double n = static_cast<double>(p.steps);
  r.per_step = {.physics = p.physics / n,
                .touch = p.touch / n,
                .vision = p.vision / n,
                .proprio = p.proprio / n,
                .vestibular = p.vestibular / n,
                .other = 0,
                .steps = p.steps};
  // "Other" is everything in the step not attributed to a module (task, bookkeeping).
  const double attributed = r.per_step.physics + r.per_step.touch + r.per_step.vision +
                            r.per_step.proprio + r.per_step.vestibular;
  r.per_step.other = std::max(0.0, env_seconds / steps - attributed);
  return r;
}

BenchResult run_bench(const Config& config, int steps, std::uint64_t seed) {
  const auto assets = envs::make_assets(config);
  envs::BabyBenchEnv env(assets, seed);
  return time_env(env, assets->model.get(), config.actuation_model, config.frame_skip,
                  assets->settled, steps, seed);
}

BenchResult run_sample_bench(const std::string& name, int steps, std::uint64_t seed) {
  const auto assets = envs::make_sample_assets(name);
  auto env = envs::make_sample_env(assets, seed);
  return time_env(*env, env->model(), assets->actuation, assets->definition.frame_skip,
                  assets->init, steps, seed);
}

void print_bench(const std::string& label, const BenchResult& r, bool json) {
  {
    const envs::Profile& p = r.per_step;
    const nlohmann::ordered_json modules = {
        {"physics", p.physics * 1e6},       {"touch", p.touch * 1e6},
        {"vision", p.vision * 1e6},         {"proprioception", p.proprio * 1e6},
        {"vestibular", p.vestibular * 1e6}, {"other", p.other * 1e6}};
    if (json) {
      const nlohmann::ordered_json out = {{"config", label},
                                          {"steps", r.steps},
                                          {"frame_skip", r.frame_skip},
                                          {"env_steps_per_s", r.env_steps_per_s},
                                          {"bare_steps_per_s", r.bare_steps_per_s},
                                          {"ratio", r.ratio},
                                          {"realtime_factor", r.realtime_factor},
                                          {"modules_us", modules}};
      std::printf("%s\n", out.dump(2).c_str());
      return;
    }
    std::printf("%s: %d env steps (frame_skip %d)\n", label.c_str(), r.steps, r.frame_skip);
    std::printf("  per env step (us):");
    for (const auto& [name, us] : modules.items()) {
      std::printf(" %s %.1f", name.c_str(), us.get<double>());
    }
    std::printf("\n  env   %10.0f steps/s  (%.1fx real time)\n", r.env_steps_per_s,
                r.realtime_factor);
    std::printf("  bare  %10.0f mj_step/s on the same model\n", r.bare_steps_per_s);
    std::printf("  ratio %10.2f  (env step time / frame_skip bare steps)\n", r.ratio);
  }
}

}  // namespace

void register_bench(CLI::App& app) {
  struct Options {
    std::string config;
    std::string env;
    int steps = 2000;
    std::uint64_t seed = 0;
    bool json = false;
  };
  auto opts = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "bench", "Measure env steps/s with a random policy against bare mj_step on the same model");
  cmd->add_option("--config", opts->config, "BabyBench YAML config");
  cmd->add_option("--env", opts->env, "MIMo sample env (MIMoReach-v0, ...; all: every one)");
  cmd->add_option("--steps", opts->steps, "Env steps to time")->check(CLI::Range(1, 100000000));
  cmd->add_option("--seed", opts->seed, "Seed of the env and the random policy")->check(kSeed);
  cmd->add_flag("--json", opts->json, "Print one JSON object");
  cmd->callback([opts] {
    if (opts->config.empty() == opts->env.empty()) {
      throw UserError("bench: give either --config FILE or --env NAME");
    }
    std::vector<std::string> names = {opts->env};
    if (opts->env == "all") names = envs::sample_env_names();
    for (const std::string& name : names) {
      const std::string label = opts->config.empty() ? name : opts->config;
      const BenchResult r = opts->config.empty()
                                ? run_sample_bench(name, opts->steps, opts->seed)
                                : run_bench(load_config(opts->config), opts->steps, opts->seed);
      print_bench(label, r, opts->json);
    }
  });
}

}  // namespace cradle::apps

// `cradle bench --config FILE | --env NAME [--steps N] [--seed S] [--json]`: env steps/s with a
// random policy, per-module time per step, and the bare mj_step loop on the same compiled model
// replaying the controls the env wrote from the same start state, in alternating blocks (CPU time
// of the thread; the ratio is the blocks' median). --env takes a MIMo sample env (MIMoReach-v0,
// ...; "all" runs every one).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "apps/bench_report.h"
#include "apps/cli_checks.h"
#include "apps/commands.h"
#include "core/config.h"
#include "core/error.h"
#include "core/mj_replay.h"
#include "core/replay_bench.h"
#include "core/rng.h"
#include "envs/babybench.h"
#include "envs/mimo/sample_env.h"
#include "sim/sim.h"

namespace cradle::apps {
namespace {

struct BenchResult {
  double env_steps_per_s = 0, bare_steps_per_s = 0, realtime_factor = 0;
  double env_us = 0, bare_us = 0;  // CPU time per env step (bare: its frame_skip mj_steps)
  envs::Profile per_step;          // seconds per env step
  int steps = 0, frame_skip = 1;
  BlockTiming timing;
};

constexpr int kBlocks = 20;          // ratio samples per run
constexpr long kMinBlockSteps = 50;  // shorter blocks time too little to compare

// The env's steps with random actions, and the bare mj_step loop replaying the controls the env
// wrote, segment by segment (core/replay_bench.h).
template <typename EnvT>
struct MimoHooks {
  EnvT& env;
  MjReplay& recorder;
  mjData* bare;
  Rng& rng;
  std::vector<double>& actions;  // the segment's actions, drawn before it is timed
  const mjModel* m = nullptr;
  double env_wall_s = 0;  // wall time of the env segments (the modules' profile is wall time)
  std::chrono::steady_clock::time_point wall;

  size_t width() const { return env.action_space().size(); }
  void begin(long n) {
    const Box& space = env.action_space();
    const size_t a = width();
    space.sample(rng, std::span<double>(actions).first(static_cast<size_t>(n) * a));
    m = env.model();
    recorder.begin(m, env.data(), bare);
    wall = std::chrono::steady_clock::now();
  }
  bool step(long i) {
    const size_t a = width();
    const envs::StepResult r =
        env.step(std::span<const double>(actions).subspan(static_cast<size_t>(i) * a, a));
    return r.terminated || r.truncated;
  }
  void end() {
    env_wall_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - wall).count();
    recorder.end();
  }
  void replay() { recorder.replay(m, bare); }
  bool exact() { return recorder.complete() && MjReplay::same_state(m, env.data(), bare); }
  void next_episode() { env.reset(); }
};

// Times `steps` env steps with random actions against the bare physics replaying them.
template <typename EnvT>
BenchResult time_env(EnvT& env, int frame_skip, int steps, std::uint64_t seed) {
  env.reset(seed);
  env.clear_profile();
  const long block_steps = block_size(steps, kBlocks, kMinBlockSteps);
  const mjModel* m = env.model();
  MjReplay recorder(m, 2 * block_steps * frame_skip + 16, /*applied_forces=*/false);
  sim::DataPtr bare(mj_makeData(m));
  if (!bare) throw UserError("MuJoCo: cannot allocate the simulation data (out of memory?)");
  Rng rng(seed + 1);
  std::vector<double> actions(static_cast<size_t>(block_steps) * env.action_space().size());
  MimoHooks<EnvT> hooks{
      .env = env, .recorder = recorder, .bare = bare.get(), .rng = rng, .actions = actions};
  BenchResult r;
  r.timing = time_blocks(steps, block_steps, hooks);
  const BlockTiming& t = r.timing;
  r.steps = steps;
  r.frame_skip = frame_skip;
  r.env_steps_per_s = steps / t.env_s;
  r.bare_steps_per_s = static_cast<double>(steps) * frame_skip / t.bare_s;
  r.env_us = 1e6 * t.env_s / steps;
  r.bare_us = 1e6 * t.bare_s / steps;
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
  r.per_step.other = std::max(0.0, hooks.env_wall_s / steps - attributed);
  return r;
}

BenchResult run_bench(const Config& config, int steps, std::uint64_t seed) {
  const auto assets = envs::make_assets(config);
  envs::BabyBenchEnv env(assets, seed);
  return time_env(env, config.frame_skip, steps, seed);
}

BenchResult run_sample_bench(const std::string& name, int steps, std::uint64_t seed) {
  const auto assets = envs::make_sample_assets(name);
  auto env = envs::make_sample_env(assets, seed);
  return time_env(*env, assets->definition.frame_skip, steps, seed);
}

void print_bench(const std::string& label, const BenchResult& r, bool json) {
  const envs::Profile& p = r.per_step;
  const Spread& ratio = r.timing.ratio;
  const nlohmann::ordered_json modules = {
      {"physics", p.physics * 1e6},       {"touch", p.touch * 1e6},
      {"vision", p.vision * 1e6},         {"proprioception", p.proprio * 1e6},
      {"vestibular", p.vestibular * 1e6}, {"other", p.other * 1e6}};
  if (json) {
    nlohmann::ordered_json out = {{"config", label},
                                  {"steps", r.steps},
                                  {"frame_skip", r.frame_skip},
                                  {"env_steps_per_s", r.env_steps_per_s},
                                  {"bare_steps_per_s", r.bare_steps_per_s},
                                  {"ratio", ratio.median}};
    add_block_timing(out, r.timing, r.env_us, r.bare_us);
    out["realtime_factor"] = r.realtime_factor;
    out["modules_us"] = modules;
    std::printf("%s\n", out.dump(2).c_str());
    return;
  }
  std::printf("%s: %d env steps (frame_skip %d)\n", label.c_str(), r.steps, r.frame_skip);
  std::printf("  per env step (us):");
  for (const auto& [name, us] : modules.items()) {
    std::printf(" %s %.1f", name.c_str(), us.get<double>());
  }
  std::printf("\n  env   %10.0f steps/s  (%.1fx real time)  %.1f us per step\n", r.env_steps_per_s,
              r.realtime_factor, r.env_us);
  std::printf("  bare  %10.0f mj_step/s on the same model  %.1f us per env step\n",
              r.bare_steps_per_s, r.bare_us);
  std::printf(
      "  ratio %10.2f  median of %d blocks of %ld steps (min %.2f, quartiles %.2f-%.2f, "
      "max %.2f)\n",
      ratio.median, ratio.count, r.timing.block_steps, ratio.min, ratio.q1, ratio.q3, ratio.max);
  std::printf("  replay %s\n", r.timing.replay_exact
                                   ? "exact: the bare loop ends every block in the env's state"
                                   : "inexact: the env changes its state outside mj_step");
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
      "bench",
      "Measure env steps/s with a random policy against bare mj_step on the same model, which "
      "replays the env's controls from the same start state in alternating blocks (CPU time; "
      "ratio: the blocks' median, with min, quartiles and max)");
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

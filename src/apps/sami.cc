// `cradle sami random|bench|info|train|evaluate|table`: the SaMI environment family (src/sami/)
// and its learners (src/learn/meta/, src/train/sami/). `random` runs random episodes and prints
// each episode's return and hidden parameters (optionally an mp4 and a PNG of the last frame);
// `bench` measures env steps/s against the bare mj_steps replaying the env's controls; `info`
// prints the spaces and the task sets of every split; `train` / `evaluate` / `table` train a
// method, evaluate it on a split and tabulate runs as the paper's Table 1/2; `build-scene` writes
// one task's model as MJCF.
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "apps/bench_report.h"
#include "apps/cli_checks.h"
#include "apps/commands.h"
#include "apps/distributed_flags.h"
#include "apps/interrupt.h"
#include "core/error.h"
#include "core/folders.h"
#include "core/image.h"
#include "core/rng.h"
#include "eval/video.h"
#include "learn/hyperparams.h"
#include "learn/meta/sami_learner.h"
#include "sami/env.h"
#include "sami/render.h"
#include "sami/scene.h"
#include "sami/task.h"
#include "sami/throughput.h"
#include "train/sami/sami_experiment.h"

namespace cradle::apps {
namespace {

std::string eval_num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%g", v);
  return buf;
}

std::string list(const std::vector<double>& values) {
  std::string out;
  for (double v : values) out += (out.empty() ? "" : ", ") + eval_num(v);
  return "{" + out + "}";
}

std::string cripple_text(const std::vector<int>& joints) {
  return "[" + sami::joints_text(joints, ",") + "]";
}

// The episode's hidden parameters, as `random` and `build-scene` print them.
std::string hidden_text(const sami::Spec& spec, const sami::Info& info) {
  if (spec.id == sami::EnvId::kPandaPush) {
    return "friction " + eval_num(info.friction) + ", cube mass " + eval_num(info.mass);
  }
  return "mass x" + eval_num(info.mass) + ", damping x" + eval_num(info.damping) + ", crippled " +
         cripple_text(info.crippled) +
         (info.crippled.empty() || info.masked ? "" : " (geometry only)");
}

// Writes the model of task set `task` of the split (values drawn by a reset with `seed`) as
// <out>/scene.xml. Every check comes before anything is written.
void build_scene(const std::string& name, const std::string& split, int task, std::uint64_t seed,
                 const std::string& out, bool overwrite) {
  namespace fs = std::filesystem;
  const sami::EnvId id = sami::env_from_name(name);
  std::vector<sami::TaskSet> sets = sami::task_sets(id, split);
  const int n = static_cast<int>(sets.size());
  if (task < 0 || task >= n) {
    throw UserError("--task " + std::to_string(task) + ": " + name + "'s split " + split +
                    " has task sets 0 to " + std::to_string(n - 1));
  }
  const fs::path dir(out);
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec)) {
    throw UserError("--out " + out + " is a file; expected a folder");
  }
  if (fs::is_directory(dir, ec) && !fs::is_empty(dir, ec) && !overwrite) {
    throw UserError("--out " + out + " is not empty; pass --overwrite to replace its scene.xml");
  }
  auto env = sami::make_env(id, {std::move(sets[task])}, seed);
  env->reset(seed);
  const std::string xml = sami::scene_xml(*env);
  make_folder(dir, "cannot create folder");
  const fs::path file = dir / "scene.xml";
  {
    std::ofstream stream(file, std::ios::binary);
    stream << xml;
    if (!stream) throw UserError("cannot write '" + file.string() + "'");
  }
  std::printf("wrote %s: %s, split %s, task set %d, %s\n", file.string().c_str(), name.c_str(),
              split.c_str(), task, hidden_text(env->spec(), env->info()).c_str());
}

void random_episodes(const std::string& name, const std::string& split, int episodes,
                     std::uint64_t seed, const std::string& video, const std::string& png, int size,
                     int max_steps) {
  auto env = sami::make_env(name, split, seed);
  const sami::Spec& spec = env->spec();
  std::unique_ptr<sami::Renderer> renderer;
  std::unique_ptr<eval::VideoWriter> writer;
  std::vector<std::uint8_t> frame;
  if (!video.empty() || !png.empty()) {
    renderer = std::make_unique<sami::Renderer>(*env, size, size * 3 / 4);
    frame.resize(static_cast<size_t>(renderer->width()) * renderer->height() * 3);
  }
  if (!video.empty()) {
    writer = std::make_unique<eval::VideoWriter>(video, renderer->width(), renderer->height(),
                                                 1.0 / spec.dt);
  }
  Rng rng(seed + 1);
  std::vector<double> action(spec.action_size);
  for (int e = 0; e < episodes; ++e) {
    env->reset(e == 0 ? std::optional<std::uint64_t>(seed) : std::nullopt);
    double ret = 0;
    sami::StepResult r;
    do {
      for (double& a : action) a = rng.uniform(spec.action_low, spec.action_high);
      r = env->step(action);
      ret += r.reward;
      if (writer) {
        renderer->render(*env, frame);
        writer->write(frame);
      }
    } while (!r.terminated && !r.truncated && (max_steps == 0 || env->info().steps < max_steps));
    const sami::Info& info = env->info();
    std::printf("episode %d: return %.3f, %d steps, task set %d, %s", e, ret, info.steps,
                info.task_set, hidden_text(spec, info).c_str());
    if (spec.id == sami::EnvId::kPandaPush) {
      std::printf(", success %d, skill %s", info.is_success,
                  std::string(sami::skill_name(info.episode_skill)).c_str());
    }
    std::printf("\n");
  }
  if (writer) {
    writer->close();
    std::printf("video: %s (%d frames)\n", video.c_str(), writer->frames());
  }
  if (!png.empty()) {
    renderer->render(*env, frame);
    write_png({renderer->width(), renderer->height(), frame}, png);
    std::printf("frame: %s\n", png.c_str());
  }
}

// train / evaluate / table.
void register_learners(CLI::App& cmd) {
  struct Options {
    train::SamiTrainOptions train;
    DistributedFlags dist;
    std::vector<std::string> hp;
    std::string out;
    train::SamiEvalOptions eval;
    std::string run;
    std::vector<std::string> runs;
    std::string table_out;
  };
  auto opts = std::make_shared<Options>();
  CLI::App* tr = cmd.add_subcommand("train",
                                    "Train a SaMI method (TESAC, CCM, SaTESAC, SaCCM, "
                                    "SaCCMAll) on an env's training task sets");
  tr->add_option("--env", opts->train.env, "Env name (see `cradle sami info --env all`)");
  tr->add_option("--method,--algo", opts->train.method,
                 "TESAC, CCM, SaTESAC, SaCCM or SaCCMAll (or the learner names tesac, ccm, "
                 "satesac, saccm, saccm_all)");
  tr->add_option("--seed", opts->train.seed, "Seed")->check(kSeed);
  tr->add_option("--steps-per-env", opts->train.steps_per_env,
                 "Env steps per training env (default: the env's, 500000; PandaPush 1000000)")
      ->check(CLI::Range(1L, 10'000'000'000L))
      ->default_str("");  // 0 stands for the env's budget
  CLI::Option* steps =
      tr->add_option("--steps", opts->train.steps,
                     "Env steps in all (over the training envs; rounded up to a multiple of "
                     "their number) instead of --steps-per-env")
          ->check(CLI::Range(1L, 100'000'000'000L))
          ->default_str("");
  steps->excludes("--steps-per-env");
  tr->add_option("--hp", opts->hp, "Hyperparameter override name=value (repeatable)");
  tr->add_option("--out", opts->out, "Run folder (default runs/sami/<env>_<method>_<seed>)");
  tr->add_flag("--resume", opts->train.resume, "Continue the run in --out from its checkpoint");
  tr->add_flag("--overwrite", opts->train.overwrite, "Replace the run already in --out");
  tr->add_option("--checkpoint-every", opts->train.checkpoint_every,
                 "Env steps per training env between checkpoints")
      ->check(CLI::Range(1L, 10'000'000'000L));
  tr->add_flag("!--no-progress", opts->train.progress_bar, "No progress bar");
  add_distributed_flags(tr, opts->dist);
  tr->callback([opts, tr] {
    // --resume --out DIR continues DIR's env, method and seed (its run.json): one left out is the
    // run's, one given must be the run's (sami_train refuses another env or method, the seed is
    // checked here). Without --out, they name the folder runs/sami/<env>_<method>_<seed>.
    if (opts->train.resume && !opts->out.empty()) {
      if (tr->get_option("--env")->count() == 0) opts->train.env.clear();
      if (tr->get_option("--method")->count() == 0) opts->train.method.clear();
      if (tr->get_option("--seed")->count() > 0) {
        const std::filesystem::path run = opts->out;
        const std::uint64_t saved = train::read_sami_run(run).seed;
        if (saved != opts->train.seed) {
          throw UserError("sami train --resume: " + (run / "run.json").string() +
                          " is a run of --seed " + std::to_string(saved) + ", not --seed " +
                          std::to_string(opts->train.seed) + " (leave --seed out to continue it)");
        }
      }
    }
    // The learner registry's names (`cradle train --algo saccm`) name the same methods.
    if (const std::string_view m = learn::meta::sami_method(opts->train.method); !m.empty())
      opts->train.method = std::string(m);
    opts->train.hyperparameters = learn::parse_hyperparameter_flags(opts->hp);
    opts->train.out = opts->out;
    opts->train.stop = stop_on({SIGINT, SIGTERM});
    train::SamiTrainResult r;
    const int rank = run_as_rank(opts->dist, [&](std::shared_ptr<learn::GradSync> sync) {
      opts->train.sync = std::move(sync);
      r = train::sami_train(opts->train);
      opts->train.sync.reset();  // the ranks' group ends with this call
      return r.parameter_hash;
    });
    // Rank 0 reports the run; a stopped rank exits 130.
    if (rank == 0) {
      std::printf(
          "%s: %ld env steps, %ld gradient steps, %.0f env steps/s, %.2f gradient steps/s, "
          "last return %.3f\ncheckpoint: %s\n",
          r.run.string().c_str(), r.steps, r.updates, r.sps, r.gradient_steps_per_s, r.last_return,
          r.checkpoint.string().c_str());
    }
    if (r.stopped) {
      if (rank == 0) {
        std::printf("stopped by a signal; continue with: cradle sami train --out %s --resume\n",
                    r.run.string().c_str());
      }
      throw Stopped{};  // exit 130
    }
  });

  CLI::App* ev = cmd.add_subcommand("evaluate", "Evaluate a trained run on a split, per task cell");
  ev->add_option("--run", opts->run, "Run folder of `cradle sami train`")->required();
  ev->add_option("--split", opts->eval.split, "train, moderate or extreme");
  ev->add_option("--episodes", opts->eval.episodes, "Episodes per task set (cell)")
      ->check(CLI::Range(1, 100000));
  ev->add_option("--seed", opts->eval.seed, "Seed of the evaluation envs")->check(kSeed);
  ev->add_flag("--video", opts->eval.video, "Write eval_<split>.mp4 (first episode per cell)");
  ev->callback([opts] {
    opts->eval.run = opts->run;
    const train::SamiEvalResult r = train::sami_evaluate(opts->eval);
    // Panda's cells: success and the skill mix; locomotion's (long names last): the returns.
    if (r.skills) {
      std::printf("%-44s %8s %8s %12s %6s %6s %6s\n", "cell", "episodes", "success", "return",
                  "push", "roll", "pick");
    } else {
      std::printf("%8s %12s %10s  %s\n", "episodes", "return", "std", "cell");
    }
    for (const train::SamiCell& c : r.cells) {
      if (r.skills) {
        std::printf("%-44s %8d %8.2f %12.2f %6.2f %6.2f %6.2f\n", c.name.c_str(), c.episodes,
                    c.success_rate, c.mean_return, c.push, c.roll, c.pick_and_place);
      } else {
        std::printf("%8d %12.2f %10.2f  %s\n", c.episodes, c.mean_return, c.std_return,
                    c.name.c_str());
      }
    }
    std::printf("%s: ", r.split.c_str());
    if (r.skills) std::printf("success %.3f, ", r.success_rate);
    std::printf("mean return %.2f\nwritten: %s, %s, %s\n", r.mean_return, r.json.string().c_str(),
                r.csv.string().c_str(), r.contexts.string().c_str());
  });

  CLI::App* tb = cmd.add_subcommand("table", "The paper's Table 1/2 over evaluated runs");
  tb->add_option("runs", opts->runs, "Run folders (evaluated)")->required();
  tb->add_option("--out", opts->table_out, "Also write the table to this file");
  tb->callback([opts] {
    std::vector<std::filesystem::path> runs(opts->runs.begin(), opts->runs.end());
    std::printf("%s", train::sami_table(runs, opts->table_out).c_str());
  });
}

std::vector<sami::EnvId> envs_named(const std::string& name) {
  if (name == "all") {
    const auto all = sami::all_envs();
    return {all.begin(), all.end()};
  }
  return {sami::env_from_name(name)};
}

}  // namespace

void register_sami(CLI::App& app) {
  struct Options {
    std::string env = "HalfCheetah";
    std::string split = "train";
    int episodes = 3;
    std::uint64_t seed = 0;
    std::string video, png;
    int size = 320;
    long steps = 20000;
    int max_steps = 0;
    bool json = false;
  };
  auto opts = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("sami", "SaMI environments (locomotion family, Panda push)");
  cmd->require_subcommand(1);

  CLI::App* random = cmd->add_subcommand("random", "Random episodes; prints hidden parameters");
  random->add_option("--env", opts->env, "Env name (see `cradle sami info --env all`)");
  random->add_option("--split", opts->split, "train, moderate, extreme or a task-set .yml file");
  random->add_option("--episodes", opts->episodes, "Episodes")->check(CLI::Range(1, 100000));
  random->add_option("--seed", opts->seed, "Seed of the env and the random policy")->check(kSeed);
  random->add_option("--video", opts->video, "Write an mp4 of all episodes");
  random->add_option("--png", opts->png, "Write a PNG of the last frame");
  random->add_option("--size", opts->size, "Picture width (height 3/4 of it)")
      ->check(CLI::Range(16, 2048));
  random->add_option("--max-steps", opts->max_steps, "End episodes after this many steps (0: none)")
      ->check(CLI::Range(0, 100000000));
  random->callback([opts] {
    random_episodes(opts->env, opts->split, opts->episodes, opts->seed, opts->video, opts->png,
                    opts->size, opts->max_steps);
  });

  CLI::App* bench = cmd->add_subcommand(
      "bench",
      "Env steps/s against bare mj_step replaying the env's controls from the same start state on "
      "the episode's model, in alternating blocks (CPU time; ratio: the blocks' median and range)");
  bench->add_option("--env", opts->env, "Env name or all");
  bench->add_option("--steps", opts->steps, "Env steps per env")
      ->check(CLI::Range(100L, 100000000L));
  bench->add_option("--seed", opts->seed, "Seed of the env and the random actions")->check(kSeed);
  bench->add_flag("--json", opts->json, "Print one JSON array");
  bench->callback([opts] {
    const std::vector<sami::EnvId> ids = envs_named(opts->env);
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    if (!opts->json) {
      std::printf("%-20s %12s %12s %7s %13s %9s %9s  %s\n", "env", "env steps/s", "bare steps/s",
                  "ratio", "ratio min-max", "env us", "bare us", "replay");
    }
    for (sami::EnvId id : ids) {
      const sami::Throughput t = sami::measure_throughput(id, opts->steps, opts->seed);
      const Spread& s = t.timing.ratio;
      const std::string name(sami::env_name(id));
      if (opts->json) {
        out.push_back({{"env", name},
                       {"steps", t.timing.steps},
                       {"env_steps_per_s", t.env_steps_per_s},
                       {"bare_steps_per_s", t.bare_steps_per_s},
                       {"ratio", t.ratio}});
        add_block_timing(out.back(), t.timing, t.env_us, t.bare_us);
        continue;
      }
      std::printf("%-20s %12.0f %12.0f %7.3f %6.3f-%6.3f %9.1f %9.1f  %s\n", name.c_str(),
                  t.env_steps_per_s, t.bare_steps_per_s, t.ratio, s.min, s.max, t.env_us, t.bare_us,
                  t.timing.replay_exact ? "exact" : "inexact");
    }
    if (opts->json) std::printf("%s\n", out.dump(2).c_str());
  });

  register_learners(*cmd);

  struct SceneOptions {
    std::string env, split = "train", out;
    int task = 0;
    std::uint64_t seed = 0;
    bool overwrite = false;
  };
  auto scene_opts = std::make_shared<SceneOptions>();
  CLI::App* scene = cmd->add_subcommand(
      "build-scene",
      "Write one task's model (hidden parameters applied) as <out>/scene.xml for MuJoCo's "
      "simulate");
  scene->add_option("--env", scene_opts->env, "Env name (see `cradle sami info --env all`)")
      ->required();
  scene->add_option("--split", scene_opts->split,
                    "train, moderate, extreme or a task-set .yml file");
  scene->add_option("--task", scene_opts->task,
                    "Task set of the split, from 0 (`cradle sami info` lists them)");
  scene->add_option("--seed", scene_opts->seed,
                    "Seed of the reset that draws the task set's values");
  scene->add_option("--out", scene_opts->out, "Output folder (new or empty)")->required();
  scene->add_flag("--overwrite", scene_opts->overwrite,
                  "Write into a folder that is not empty (replaces its scene.xml)");
  scene->callback([scene_opts] {
    const SceneOptions& o = *scene_opts;
    build_scene(o.env, o.split, o.task, o.seed, o.out, o.overwrite);
  });

  CLI::App* info = cmd->add_subcommand("info", "Spaces and task sets of an env");
  info->add_option("--env", opts->env, "Env name or all");
  info->callback([opts] {
    for (sami::EnvId id : envs_named(opts->env)) {
      const sami::Spec s = sami::env_spec(id);
      std::printf("%s: action %d in [%g, %g], horizon %d, %d x mj_step (dt %g s)\n", s.name.c_str(),
                  s.action_size, s.action_low, s.action_high, s.horizon, s.frame_skip, s.dt);
      for (const sami::ObsKey& k : s.keys) {
        std::printf("  obs %s: %d %s\n", k.name.c_str(), k.size,
                    std::string(dtype_name(s.obs_dtype)).c_str());
      }
      for (sami::Split split :
           {sami::Split::kTrain, sami::Split::kModerate, sami::Split::kExtreme}) {
        const auto sets = sami::split_sets(id, split);
        std::printf("  %s: %zu task sets\n", std::string(sami::split_name(split)).c_str(),
                    sets.size());
        for (const sami::TaskSet& t : sets) {
          if (!t.cells.empty()) {
            std::printf("    cell friction %g, cube mass %g\n", t.cells[0][0], t.cells[0][1]);
            continue;
          }
          std::string cripple;
          for (const auto& c : t.cripple) cripple += cripple_text(c);
          std::printf("    mass %s damping %s%s%s%s\n", list(t.mass).c_str(),
                      list(t.damping).c_str(), cripple.empty() ? "" : " cripple ", cripple.c_str(),
                      !cripple.empty() && !t.mask ? " (geometry only)" : "");
        }
      }
    }
  });
}

}  // namespace cradle::apps

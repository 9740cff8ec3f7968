#include "train/trainer.h"

#include <fnmatch.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iostream>
#include <iterator>
#include <limits>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/folders.h"
#include "core/jsonl.h"
#include "core/sealed_file.h"
#include "envs/babybench.h"
#include "envs/registry.h"
#include "eval/figures.h"
#include "eval/log_check.h"
#include "eval/scores.h"
#include "learn/grad_sync.h"
#include "learn/hyperparams.h"
#include "learn/intrinsic/reward.h"
#include "learn/registry.h"
#include "learn/run_files.h"
#include "learn/vector_env.h"
#include "train/babybench_vector.h"
#include "train/curriculum_env.h"
#include "train/env_vector.h"
#include "train/families.h"
#include "train/loop.h"
#include "train/task_space.h"

namespace cradle::train {
namespace {

namespace fs = std::filesystem;
// The run drives a learner: checkpoints, run state, stats and intrinsic rewards are learn's.
using namespace cradle::learn;
using Clock = std::chrono::steady_clock;

// Columns of logs/progress.csv, CleanRL's names: the run's own, then "charts/success_rate" for
// envs whose info has "is_success", then the learner's report keys under their group's prefix
// (then the keys of its own, extra_report_keys, as "losses/<key>").
const char* const kRunColumns[] = {
    "global_step",    "time", "charts/SPS", "charts/episodic_return", "charts/episodic_length",
    "behaviour/score"};
constexpr int kSuccessColumn = static_cast<int>(std::size(kRunColumns));
const char* const kReportColumns[] = {
    "losses/value_loss",    "losses/policy_loss",   "losses/entropy",
    "losses/approx_kl",     "losses/clip_fraction", "losses/explained_variance",
    "charts/learning_rate", "losses/qf_loss",       "losses/actor_loss",
    "losses/alpha",         "losses/alpha_loss",    "losses/qf1_values",
    "perf/collect_seconds", "perf/update_seconds"};

// A report key's value (NaN when the learner does not report it).
double loss(const TrainStats& s, const std::string& key) {
  const auto it = s.losses.find(key);
  return it == s.losses.end() ? std::nan("") : it->second;
}

// Learning curves from progress.csv's rows (matplotlib): the return; the behaviour score where
// episodes scored one (BabyBench's, Panda push's); the success rate in column `success` (-1:
// none) where the env's info says "is_success" (drawn before the first episode ends too).
void plot_curves(const std::vector<std::vector<double>>& rows, bool intrinsic, int success,
                 const fs::path& dir) {
  struct Curve {
    int column;
    const char *title, *series, *y_label, *file;
  };
  const Curve curves[] = {
      {3, intrinsic ? "Training: episodic return (env + intrinsic)" : "Training: episodic return",
       "episodic return", "return", "learning_curve_return.png"},
      {5, "Training: behaviour score per episode", "behaviour score", "score",
       "learning_curve_score.png"},
      {success, "Training: success rate", "success rate", "success rate",
       "learning_curve_success.png"}};
  eval::Figures figures;
  for (const Curve& c : curves) {
    if (c.column < 0) continue;
    eval::LinePlot plot{.title = c.title, .x_label = "env steps", .y_label = c.y_label};
    eval::Series& s = plot.series.emplace_back(eval::Series{.label = c.series});
    for (const auto& r : rows) {
      if (!std::isnan(r[c.column])) {
        s.x.push_back(r[0]);
        s.y.push_back(r[c.column]);
      }
    }
    if (c.column == 5 && s.x.empty()) continue;                   // no episode scored behaviour
    if (c.column == success) plot.y_range = std::pair{0.0, 1.0};  // a share
    figures.add(std::move(plot), dir / c.file);
  }
  figures.draw(dir / "figures.json");
}

// The behaviour scores and successes of the episodes ended since the last progress row.
struct EpisodeTally {
  double score_sum = 0, scored = 0, successes = 0, ended = 0;
};

// Data-parallel: the ranks' episodes, scores and successes pooled into `stats` and `tally`;
// returns whether any rank was asked to stop (so that all stop at the same update).
bool pool_progress(GradSync& sync, TrainStats& stats, EpisodeTally& tally, bool stop) {
  const bool none = stats.episodes == 0;
  std::vector<double> sums = {static_cast<double>(stats.episodes),
                              none ? 0 : stats.episodes * stats.episodic_return,
                              none ? 0 : stats.episodes * stats.episodic_length,
                              tally.score_sum,
                              tally.scored,
                              tally.successes,
                              tally.ended,
                              stop ? 1.0 : 0.0};
  sync.all_reduce_sum(sums);
  stats.episodes = static_cast<int>(sums[0]);
  stats.episodic_return = sums[0] > 0 ? sums[1] / sums[0] : std::nan("");
  stats.episodic_length = sums[0] > 0 ? sums[2] / sums[0] : std::nan("");
  tally = {sums[3], sums[4], sums[5], sums[6]};
  return sums[7] > 0;
}

// What a run left in `dir` (its latest checkpoint, or its progress rows); empty when none.
fs::path held_run(const fs::path& dir) {
  std::error_code ec;
  if (fs::exists(dir / "checkpoints" / "latest.ckpt", ec))
    return dir / "checkpoints" / "latest.ckpt";
  // A run that failed before its first report leaves progress.csv's header only.
  std::ifstream in(dir / "logs" / "progress.csv");
  std::string line;
  if (std::getline(in, line) && std::getline(in, line) && !line.empty())
    return dir / "logs" / "progress.csv";
  return {};
}
}  // namespace

namespace {

// One run, built stage by stage: train() names the stages in order, and what a stage decides the
// later ones read here.
struct Run {
  Run(const Config& c, const TrainOptions& o) : config(c), options(o), env_config(c) {}
  const Config& config;
  const TrainOptions& options;
  // check_options: the run's settings (a resumed run's from its checkpoint).
  bool by_id = false;  // an env id of any family but BabyBench's configs
  std::string env_id;
  std::string algorithm;
  std::map<std::string, std::string> hyperparameters;
  RunState resumed;
  GradSync* sync = nullptr;  // a data-parallel run's ranks
  int rank = 0;
  std::optional<CurriculumSpec> curriculum_spec;
  fs::path dir, checkpoints, latest;
  // open_run_folder: where this rank's envs log (the config's folder on rank 0).
  Config env_config;
  fs::path log_file;
  long kept_episodes = -1;
  // make_curriculum (check_options builds a named teacher's controller)
  std::shared_ptr<teach::TeacherController> curriculum;
  EnvWrapper wrap;
  std::optional<JsonlWriter> teacher_log;
  // The curriculum's envs (their time in the teacher), registered as the vector makes them.
  std::mutex curriculum_envs_mutex;
  std::vector<const CurriculumEnv*> curriculum_envs;
  // make_vector
  TrainingVector training;
  std::unique_ptr<intrinsic::Composite> reward;
  // make_learner: the episodes ended since the last progress row, and the info's slot of
  // "is_success" (-1: the env has none).
  EpisodeTally tally;
  int success_slot = -1;
  std::unique_ptr<Learner> learner;
  // A run that resets its learner: the run's steps before the current learner's, and how many
  // fresh learners it has made.
  long offset = 0;
  long resets = 0;
  // open_logs: progress.csv's columns (the learner's own report keys last) and rows so far.
  std::vector<std::string> extra;
  fs::path csv_file;
  std::ofstream csv;
  std::vector<std::vector<double>> rows;
  // train_loop: when this process began training, and the run's steps then; the step of the last
  // evaluation (-1: none).
  Clock::time_point start = Clock::now();
  long first_steps = 0;
  long last_evaluated = -1;

  // The run's env steps (over every learner of a run that resets).
  long steps() const { return offset + learner->steps(); }
};

// Every option checked and the run's settings resolved; nothing is written before this.
void check_options(Run& run) {
  const TrainOptions& options = run.options;
  if (options.steps < 1) throw UserError("--steps must be at least 1");
  if (options.envs < 1) throw UserError("--envs must be at least 1");
  if (options.checkpoint_every < 1) throw UserError("--checkpoint-every must be at least 1");
  if (options.reset_every < 0) throw UserError("--reset-every must be >= 0 (0: never)");
  if (options.resume && options.overwrite)
    throw UserError("--resume and --overwrite: give one of them");
  if (options.experiment && options.experiment->evaluate_every() < 1)
    throw UserError("the run's evaluations need at least 1 env step between them");
  // Worker processes: each holds the same number of envs; their envs' teacher and batches would
  // live apart from this process's.
  if (options.procs != 0) {
    if (options.procs < 1) throw UserError("--procs must be at least 1");
    check_procs_split(options.envs, options.procs);
    if (options.async_batch != 0) throw UserError("--procs and --async-batch: give one of them");
  }
  // An env by id (any family but BabyBench's configs, which train as configs) has none of
  // BabyBench's extras: no training log, start randomisation or final evaluation.
  run.by_id = !options.env.empty();
  run.env_id = run.by_id ? registered_env_id(options.env) : "";
  if (run.by_id) {
    if (envs::env_spec(run.env_id).family == "babybench")
      throw UserError("--env " + options.env + " is a BabyBench config: train it as --config " +
                      "(cradle train --env does that for you)");
    if (options.randomize_start || options.compare_random)
      throw UserError(
          "--randomize-start and --compare-random are for BabyBench configs, not --env");
  }
  // Checkpoints inside the reports keep episodes running across them; a BabyBench checkpoint ends
  // every env's episode in the training log, so a config's run checkpoints at boundaries.
  if (!options.checkpoints_split_learning && !run.by_id) {
    throw UserError(
        "checkpoints inside the reports are for runs by env id (a BabyBench checkpoint ends the "
        "training log's episodes)");
  }
  run.dir = run.config.save_dir;
  run.checkpoints = run.dir / "checkpoints";
  run.latest = run.checkpoints / "latest.ckpt";
  if (options.resume && !fs::exists(run.latest)) {
    throw UserError("--resume: no checkpoint at '" + run.latest.string() + "'");
  }
  // A resumed run keeps its algorithm; --hp values override the checkpoint's (those that fix
  // network shapes or observation settings are then refused by load()). The logs are cut back to
  // what the checkpoint knows.
  run.algorithm = options.algorithm.empty() ? "ppo" : options.algorithm;
  run.hyperparameters = options.hyperparameters;
  // What the env's family trains the learner with comes under the user's values (SaMI's
  // learners: whole episodes as trajectories, Panda's batch sizes).
  if (run.by_id && !options.resume) {
    const envs::EnvSpec spec = envs::env_spec(run.env_id);
    if (const auto presets = family(spec.family).presets) {
      for (const auto& [name, value] : presets(spec, run.algorithm))
        run.hyperparameters.try_emplace(name, value);
    }
  }
  if (options.resume) {
    const CheckpointInfo info = read_checkpoint_info(run.latest);
    if (!options.algorithm.empty() && options.algorithm != info.algorithm) {
      throw UserError("--resume: the checkpoint is " + info.algorithm + ", not --algo " +
                      options.algorithm + " (leave --algo out to continue it)");
    }
    run.algorithm = info.algorithm;
    run.hyperparameters = parse_hyperparameter_text(info.config);
    for (const auto& [name, value] : options.hyperparameters) run.hyperparameters[name] = value;
    run.resumed = load_run_state(run.latest, nullptr);
    // An experiment continues from its own state at the checkpoint.
    if (options.experiment && run.resumed.experiment.empty()) {
      throw UserError("--resume: '" + run.latest.string() +
                      "' holds no state of this run's evaluations (written by another kind of "
                      "run); give --overwrite to start it anew");
    }
    run.offset = run.resumed.step_offset;
    run.resets = run.resumed.learner_resets;
    // The rewards are part of the task being learned: a resumed run keeps them.
    const std::string wanted =
        options.intrinsic.empty() ? "" : intrinsic::parse_intrinsic(options.intrinsic)->describe();
    if (run.resumed.intrinsic && *run.resumed.intrinsic != wanted) {
      throw UserError("--resume: the checkpoint was trained with --intrinsic '" +
                      *run.resumed.intrinsic + "', not '" + wanted + "' (give --intrinsic '" +
                      *run.resumed.intrinsic + "' to continue it)");
    }
  }
  // Data-parallel: rank r seeds with seed + r.
  run.sync = distributed(options.sync.get()) ? options.sync.get() : nullptr;
  run.rank = run.sync ? run.sync->rank() : 0;
  if (run.sync && !learn::algorithm_traits(run.algorithm).data_parallel) {
    throw UserError("--distributed trains " +
                    learn::algorithms_with(&learn::AlgorithmTraits::data_parallel) + ", not " +
                    run.algorithm);
  }
  // Async collection is the on-policy collector's (docs/async.md).
  if (options.async_batch != 0) {
    if (options.async_batch < 1 || options.async_batch >= options.envs) {
      throw UserError("--async-batch " + std::to_string(options.async_batch) +
                      " must be between 1 and --envs - 1 (" + std::to_string(options.envs - 1) +
                      "): a batch is part of the envs");
    }
    if (!learn::algorithm_traits(run.algorithm).async_collection) {
      throw UserError("--async-batch is for " +
                      learn::algorithms_with(&learn::AlgorithmTraits::async_collection, "and") +
                      " (their rollout collector), not " + run.algorithm);
    }
    if (run.sync) throw UserError("--async-batch is not available with --distributed");
  }
  // A curriculum: the task space and its teacher (a teacher given by the run needs none named in
  // the file).
  const bool own_teacher = !options.teacher.empty() || options.teacher_factory;
  if (!options.teacher.empty() && options.teacher_factory)
    throw UserError("a teacher name and a teacher object: give one of them");
  if (!options.task_space.empty() && options.curriculum)
    throw UserError("--task-space and the run's own curriculum: give one of them");
  if (!options.task_space.empty()) {
    run.curriculum_spec = load_task_space(options.task_space, /*need_teacher=*/!own_teacher);
  } else if (options.curriculum) {
    run.curriculum_spec = options.curriculum;
  } else if (own_teacher) {
    // Without a file, the teacher sets every task parameter the env declares.
    run.curriculum_spec = env_curriculum(
        run.by_id ? envs::env_spec(run.env_id)
                  : envs::EnvSpec{.id = "this BabyBench config",
                                  .family = "babybench",
                                  .parameters = envs::babybench_task_parameters(run.config)});
  }
  if (!options.teacher.empty()) run.curriculum_spec->teacher = options.teacher;
  // A named teacher's controller is built here, so that an unknown name or a bad parameter is
  // refused before --overwrite removes anything (a teacher object's, in make_curriculum).
  if (run.curriculum_spec && !options.teacher_factory)
    run.curriculum = make_controller(*run.curriculum_spec, options.seed + run.rank);
  if (options.procs != 0 && run.curriculum_spec)
    throw UserError("--procs is not available with a curriculum (--task-space or --teacher)");
  // Data-parallel: every rank must run the same command, or the collectives would not pair up.
  if (run.sync) {
    std::string hp_text;
    for (const auto& [name, value] : run.hyperparameters) hp_text += name + "=" + value + ";";
    const std::string differs = first_disagreement(
        *run.sync,
        {{"--envs", options.envs},
         {"--steps", static_cast<double>(options.steps)},
         {"--checkpoint-every", static_cast<double>(options.checkpoint_every)},
         {"--reset-every", static_cast<double>(options.reset_every)},
         {"the evaluations' interval",
          options.experiment ? static_cast<double>(options.experiment->evaluate_every()) : 0.0},
         {"--algo", static_cast<double>(std::hash<std::string>{}(run.algorithm) % (1L << 40))},
         {"--hp", static_cast<double>(std::hash<std::string>{}(hp_text) % (1L << 40))},
         {"--resume", options.resume ? 1.0 : 0.0},
         {"the checkpoint's step", static_cast<double>(run.resumed.steps)}});
    if (!differs.empty()) {
      throw UserError("the ranks run different commands (" + differs +
                      " differs): start every rank with the same arguments");
    }
  }
}

// A rank's teacher book: its path in the run folder (the checkpoint records its size by it).
std::string teacher_book(int rank) {
  return rank == 0 ? "logs/teacher.jsonl" : "ranks/" + std::to_string(rank) + "/logs/teacher.jsonl";
}

// The run folder: one that holds a run (a checkpoint, or progress rows) is never replaced
// silently: --resume continues it, --overwrite replaces it (its checkpoints, logs and plots go
// first), anything else is refused. A resumed BabyBench run's training log is cut back to the
// checkpoint's episodes. Ranks above 0 log their envs in a folder of their own (continued as
// they are on resume: the checkpoint counts rank 0's episodes).
void open_run_folder(Run& run) {
  const TrainOptions& options = run.options;
  if (!options.resume) {
    std::error_code ec;
    // What a run leaves: its checkpoint, progress rows, an experiment's files; beside a run by id,
    // its evaluations (evaluation.json, `cradle evaluate --run`'s evaluation_<checkpoint>.json,
    // videos/) and the files of its family's tools (SaMI's evaluations), by name.
    fs::path held = held_run(run.dir);
    std::vector<std::string> removed = {"checkpoints", "logs", "plots", "ranks"};
    if (options.experiment) {
      for (const std::string& file : options.experiment->files()) {
        if (held.empty() && fs::exists(run.dir / file, ec)) held = run.dir / file;
        removed.push_back(file);
      }
    }
    if (run.by_id) {
      std::vector<std::string> patterns = family(envs::env_spec(run.env_id).family).outputs;
      patterns.insert(patterns.end(), {"evaluation*.json", "videos"});
      for (const auto& entry : fs::directory_iterator(run.dir, ec)) {
        const std::string name = entry.path().filename().string();
        if (std::ranges::any_of(patterns, [&](const auto& p) {
              return fnmatch(p.c_str(), name.c_str(), 0) == 0;
            })) {
          if (held.empty()) held = entry.path();
          removed.push_back(name);
        }
      }
    }
    if (!held.empty() && !options.overwrite) {
      throw UserError("'" + run.dir.string() + "' holds a run (" + held.string() +
                      "): give --resume to continue it, --overwrite to replace it, or another "
                      "folder");
    }
    if (!held.empty() && run.rank == 0) {
      for (const std::string& sub : removed) {
        fs::remove_all(run.dir / sub, ec);
        if (ec) throw UserError("--overwrite: cannot remove '" + (run.dir / sub).string() + "'");
      }
    }
  }
  // The logs whose sizes the checkpoint records (this rank's teacher book, an experiment's) cut
  // back to them, later lines kept aside; the book is checked whole first, so that a damaged one
  // changes nothing.
  if (options.resume) {
    std::vector<std::string> logs;
    if (run.curriculum_spec) {
      logs.push_back(teacher_book(run.rank));
      const fs::path book = run.dir / logs.back();
      if (fs::exists(book)) check_teacher_book(book, run.curriculum_spec->space->dims());
    }
    if (options.experiment && run.rank == 0) {
      for (const std::string& log : options.experiment->logs()) logs.push_back(log);
    }
    for (const std::string& log : logs) {
      const auto size = run.resumed.log_sizes.find(log);
      if (size != run.resumed.log_sizes.end()) cut_to_checkpoint(run.dir / log, size->second);
    }
  }
  if (run.rank == 0) make_folder(run.dir, "cannot create the run folder");
  if (run.rank > 0)
    run.env_config.save_dir = (run.dir / "ranks" / std::to_string(run.rank)).string();
  run.log_file = fs::path(run.env_config.save_dir) / "logs" / "training.jsonl";
  if (options.resume && !run.by_id) {
    run.kept_episodes = cut_training_log(
        run.log_file, run.rank == 0 ? run.resumed.episodes : std::numeric_limits<long>::max());
  }
}

// With a task space, the teacher's controller (one per rank), the wrapper through which it sets
// every env's reset options, and its book, logs/teacher.jsonl: on resume (cut back to what the
// checkpoint knows by open_run_folder: episodes booked after it are played again) replayed into
// the teacher.
void make_curriculum(Run& run) {
  if (!run.curriculum_spec) return;
  const TrainOptions& options = run.options;
  const fs::path teacher_file = run.dir / teacher_book(run.rank);
  const std::uint64_t teacher_seed = options.seed + run.rank;
  const CurriculumSpec& spec = *run.curriculum_spec;
  if (options.teacher_factory)
    run.curriculum =
        make_controller(spec, options.teacher_factory(*spec.space, teacher_seed), teacher_seed);
  if (options.resume && fs::exists(teacher_file)) {
    replay_teacher_book(*run.curriculum, teacher_file, /*periodical=*/true);
    // The controller's step count at the checkpoint (its last booked episode may be earlier).
    const auto steps = run.resumed.teacher_steps.find(teacher_book(run.rank));
    if (steps != run.resumed.teacher_steps.end()) run.curriculum->continue_from(steps->second);
  }
  run.wrap = [&run, o = spec.env_options](std::unique_ptr<envs::Env> env) {
    auto wrapped = std::make_unique<CurriculumEnv>(std::move(env), run.curriculum, o);
    const std::lock_guard lock(run.curriculum_envs_mutex);
    run.curriculum_envs.push_back(wrapped.get());
    return wrapped;
  };
  run.teacher_log.emplace(teacher_file, options.resume);
}

// The teacher's new episodes and task snapshots (and with `dump_at`, its state at that step) to
// logs/teacher.jsonl; an experiment hears each episode.
void write_teacher_log(Run& run, std::optional<long> dump_at = std::nullopt) {
  if (!run.teacher_log) return;
  Experiment* experiment = run.rank == 0 ? run.options.experiment.get() : nullptr;
  for (const teach::EpisodeRecord& e : run.curriculum->take_episodes()) {
    run.teacher_log->write(teach::train_line(e));
    if (experiment) experiment->booked(e);
  }
  for (const teach::PeriodicalRecord& p : run.curriculum->take_periodical())
    run.teacher_log->write(
        {{"kind", "periodical"}, {"env_steps", p.env_steps}, {"tasks", p.tasks}});
  if (dump_at) run.teacher_log->write(teach::dump_line(*dump_at, run.curriculum->teacher_dump()));
  run.teacher_log->flush();
}

// The vector of envs (threads, worker processes or async batches) and the intrinsic rewards
// bound to its observations.
void make_vector(Run& run) {
  const TrainOptions& options = run.options;
  if (run.by_id) {
    for (const fs::path& logs : {run.dir / "logs", fs::path(run.env_config.save_dir) / "logs"}) {
      make_folder(logs, "cannot create");
    }
  }
  run.training = run.by_id ? make_env_training(
                                 run.env_id, options.envs, options.threads, options.seed + run.rank,
                                 run.wrap, options.async_batch, options.env_options, options.procs)
                           : make_babybench_training(run.env_config, options.envs, options.threads,
                                                     options.seed + run.rank, run.kept_episodes,
                                                     run.wrap, options.async_batch, options.procs);
  VecEnv& vec = *run.training.vec;
  // Gymnasium's convention: an env that says "is_success" at an episode's end has a success rate.
  run.success_slot = vec.info(0).find("is_success");
  for (int i = 0; i < vec.num_envs() && options.randomize_start; ++i) {
    vec.env(i).set_reset_options({{"randomize_start", 1}});
  }
  if (!options.intrinsic.empty()) {
    run.reward = intrinsic::parse_intrinsic(options.intrinsic);
    run.reward->bind(vec);
    // Every learn() resets the vector: no transition spans that reset.
    set_after_reset(vec, [&run] { run.reward->reset(*run.training.vec); });
  }
}

// A fresh learner (the run's k-th after k resets, seeded apart). Its reward hook adds the
// intrinsic rewards and the caller's terms, and tallies the behaviour score and the success of
// each episode that ends (async: the batch, whose slot i is env env_id(i)).
std::unique_ptr<Learner> fresh_learner(Run& run) {
  const TrainOptions& options = run.options;
  LearnerOptions lo{.seed = options.seed + run.rank + 7919 * static_cast<std::uint64_t>(run.resets),
                    .hyperparameters = run.hyperparameters};
  lo.sync = options.sync;
  lo.update_threads = options.update_threads;
  lo.reward_hook = [&run](const VecEnv& env, std::span<const double> actions,
                          std::span<double> rewards) {
    if (run.reward) run.reward->compute(env, actions, rewards);
    if (run.options.reward_hook) run.options.reward_hook(env, actions, rewards);
    for (int i = 0; i < env.num_envs(); ++i) {
      if (env.terminated()[i] || env.truncated()[i]) {
        const double s = env.env(i).score();
        if (!std::isnan(s)) {
          run.tally.score_sum += s;
          ++run.tally.scored;
        }
        if (run.success_slot >= 0) {
          run.tally.successes += env.info(i).flag(run.success_slot);
          ++run.tally.ended;
        }
      }
    }
  };
  return learn::make_learner(run.algorithm, *run.training.vec, lo);
}

// The learner, fresh or resumed from latest.ckpt.
void make_learner(Run& run) {
  const TrainOptions& options = run.options;
  run.learner = fresh_learner(run);
  if (!options.resume && !options.load_model.empty()) run.learner->load(options.load_model);
  // SPDL values its tasks with the student's value function.
  if (run.curriculum)
    run.curriculum->teacher().set_value_estimator(learner_value_estimator(
        [&run]() -> Learner& { return *run.learner; }, run.training.vec->observation_space()));
  if (options.resume) {
    run.learner->load(run.latest);
    load_run_state(run.latest, run.reward.get());
  }
}

// run.json (what this run is: a fresh run writes it, a resumed one keeps it) and
// logs/progress.csv, continued on resume and cut back to the checkpoint's step (later rows and a
// torn line kept aside; another version's file kept beside a new one). Rank 0 writes them.
void open_logs(Run& run) {
  const TrainOptions& options = run.options;
  std::error_code ec;
  fs::create_directories(run.checkpoints, ec);
  if (run.rank == 0 && !options.resume) {
    nlohmann::ordered_json json = {
        {"cradle_version", CRADLE_VERSION},
        {"env", run.by_id ? run.env_id : "babybench config"},
        {"family", run.by_id ? envs::env_spec(run.env_id).family : "babybench"},
        {"algorithm", run.algorithm},
        {"seed", options.seed},
        {"steps", options.steps},
        {"envs", options.envs},
        {"checkpoint_every", options.checkpoint_every},
        {"intrinsic", run.reward ? run.reward->describe() : ""},
        {"hyperparameters", run.hyperparameters},
        {"task_space", options.task_space},
        {"teacher", options.teacher},
        {"world_size", run.sync ? run.sync->world_size() : 1}};
    if (options.reset_every > 0) json["reset_every"] = options.reset_every;
    if (!run.by_id) json["config"] = to_json(run.config);
    for (const auto& [key, value] : options.run_json.items()) json[key] = value;
    write_atomically(run.dir / "run.json", json.dump(2) + "\n");
  }
  run.csv_file = run.dir / "logs" / "progress.csv";
  // The learner's own report keys follow the common columns (SaMI's: its SaNCE loss and weight).
  std::vector<std::string> columns(std::begin(kRunColumns), std::end(kRunColumns));
  if (run.success_slot >= 0) columns.push_back("charts/success_rate");
  columns.insert(columns.end(), std::begin(kReportColumns), std::end(kReportColumns));
  run.extra = extra_report_keys(run.algorithm);
  for (const std::string& key : run.extra) columns.push_back("losses/" + key);
  if (options.experiment) {
    for (const std::string& column : options.experiment->progress_columns())
      columns.push_back(column);
  }
  std::string header;
  for (size_t c = 0; c < columns.size(); ++c) header += (c ? "," : "") + columns[c];
  ProgressCut cut;
  if (options.resume && run.rank == 0)
    cut = cut_progress(run.csv_file, header, run.resumed.step_offset + run.resumed.steps);
  if (!cut.kept_aside.empty())
    std::cerr << "progress.csv rows kept aside in " << cut.kept_aside.string() << "\n";
  // The other ranks' stream writes nowhere.
  if (run.rank == 0) run.csv.open(run.csv_file, cut.append ? std::ios::app : std::ios::trunc);
  if (run.rank == 0 && !run.csv) throw UserError("cannot write '" + run.csv_file.string() + "'");
  if (!cut.append) run.csv << header << "\n";
  run.rows = std::move(cut.rows);
  for (auto& row : run.rows) row.resize(columns.size(), std::nan(""));
  // An experiment's own files, fresh or continued from its state at the checkpoint.
  if (options.experiment && run.rank == 0) {
    nlohmann::json state;
    if (options.resume) {
      state = nlohmann::json::parse(run.resumed.experiment, nullptr, /*allow_exceptions=*/false);
      if (state.is_discarded())
        throw UserError("--resume: '" + run.latest.string() +
                        "': the run state's experiment section is not JSON");
    }
    options.experiment->open(run.dir, options.resume ? &state : nullptr);
  }
}

// A checkpoint is an episode boundary: every env's episode is recorded (cut short) and the log
// flushed, so the checkpoint's episode count is the log's, and the next learn() starts fresh
// episodes exactly as a resumed run does. Rank 0 writes the run's checkpoints.
void save_checkpoint(Run& run, const std::vector<fs::path>& files) {
  run.training.end_episodes();
  if (run.training.log) run.training.log->flush();
  RunState state{.steps = run.learner->steps(),
                 .episodes = run.training.log ? run.training.log->episodes() : 0,
                 .intrinsic = run.reward ? run.reward->describe() : "",
                 .step_offset = run.offset,
                 .learner_resets = run.resets};
  // The teacher books of every rank as long as the episodes the checkpoint knows.
  if (run.teacher_log) {
    write_teacher_log(run);
    // Each rank's size and step count in its slots, summed over the ranks.
    const int ranks = run.sync ? run.sync->world_size() : 1;
    std::vector<double> counts(2 * ranks, 0.0);
    counts[2 * run.rank] = static_cast<double>(fs::file_size(run.dir / teacher_book(run.rank)));
    counts[2 * run.rank + 1] = static_cast<double>(run.curriculum->env_steps());
    if (run.sync) run.sync->all_reduce_sum(counts);
    for (int r = 0; r < ranks; ++r) {
      state.log_sizes[teacher_book(r)] = static_cast<std::uintmax_t>(counts[2 * r]);
      state.teacher_steps[teacher_book(r)] = static_cast<long>(counts[2 * r + 1]);
    }
  }
  if (run.rank > 0) return;
  // An experiment's state and the sizes of its logs.
  if (const Experiment* experiment = run.options.experiment.get()) {
    state.experiment = experiment->state().dump();
    for (const std::string& log : experiment->logs()) {
      std::error_code ec;
      const std::uintmax_t size = fs::file_size(run.dir / log, ec);
      if (!ec) state.log_sizes[log] = size;
    }
  }
  // One write; the other names are the same file (hard links, or copies where links fail).
  save_run_checkpoint(files.front(), *run.learner, run.reward.get(), state);
  for (size_t k = 1; k < files.size(); ++k) link_file(files.front(), files[k]);
  // The newest step checkpoint alone, when the run keeps only that.
  const std::string newest = "step_" + std::to_string(run.steps()) + ".ckpt";
  const bool wrote_step = std::any_of(files.begin(), files.end(),
                                      [&](const fs::path& f) { return f.filename() == newest; });
  if (!run.options.keep_step_checkpoints && wrote_step) {
    std::error_code ec;
    std::vector<fs::path> older;
    for (const auto& entry : fs::directory_iterator(run.checkpoints, ec)) {
      const std::string name = entry.path().filename().string();
      if (name.starts_with("step_") && name.ends_with(".ckpt") && name != newest)
        older.push_back(entry.path());
    }
    for (const fs::path& file : older) fs::remove(file, ec);
  }
}

// One row of logs/progress.csv (rank 0 writes them): the run's columns, the learner's report
// keys, the experiment's columns.
void write_progress_row(Run& run, const TrainStats& s, double elapsed, double score,
                        double success_rate) {
  std::vector<double> row = {
      static_cast<double>(s.steps), elapsed, s.sps, s.episodic_return, s.episodic_length, score};
  if (run.success_slot >= 0) row.push_back(success_rate);
  // A report column's key is its name after the group ("losses/alpha": alpha).
  for (const std::string column : kReportColumns)
    row.push_back(loss(s, column.substr(column.find('/') + 1)));
  for (const std::string& key : run.extra) row.push_back(loss(s, key));
  if (run.options.experiment) {
    for (double value : run.options.experiment->progress_values()) row.push_back(value);
  }
  for (size_t c = 0; c < row.size(); ++c) run.csv << (c ? "," : "") << csv_cell(row[c]);
  run.csv << "\n";
  run.csv.flush();
  if (!run.csv) throw UserError("cannot write '" + run.csv_file.string() + "'");
  run.rows.push_back(std::move(row));
}

// What an experiment's hooks see of the run now.
RunView view(const Run& run) {
  double teacher_seconds = 0;
  for (const CurriculumEnv* env : run.curriculum_envs) teacher_seconds += env->teacher_seconds();
  return {.learner = *run.learner,
          .steps = run.steps(),
          .first_steps = run.first_steps,
          .seconds = std::chrono::duration<double>(Clock::now() - run.start).count(),
          .teacher_seconds = teacher_seconds,
          .curriculum = run.curriculum.get()};
}

// An experiment's evaluation (rank 0) after the teacher's book has every ended episode, then the
// teacher's state in the book at the run's step.
void evaluate(Run& run) {
  write_teacher_log(run);
  if (run.rank == 0) {
    run.options.experiment->evaluate(view(run));
    write_teacher_log(run, run.steps());
  }
  run.last_evaluated = run.steps();
}

// A fresh learner in place of the last; the run's step count goes on from it.
void reset_learner(Run& run) {
  run.offset = run.steps();
  ++run.resets;
  run.learner = fresh_learner(run);
  if (run.rank == 0 && run.options.experiment) run.options.experiment->learner_replaced();
}

// The step checkpoint and latest.ckpt at the run's step.
void save_step_checkpoint(Run& run) {
  const fs::path step = run.checkpoints / ("step_" + std::to_string(run.steps()) + ".ckpt");
  save_checkpoint(run, {step, run.latest});
  if (run.rank == 0 && run.options.on_checkpoint) run.options.on_checkpoint(step);
}

// The loop: a progress row (and the teacher's book) at every report, a checkpoint every
// checkpoint_every steps, learning stopped at each checkpoint and continued in a new learn()
// call. With an experiment, its evaluations (before training, at each multiple of its interval,
// at the end) place the checkpoints, and the run trains exactly to them and to each fresh
// learner's step. Returns the next checkpoint's step.
long train_loop(Run& run, TrainResult& result) {
  const TrainOptions& options = run.options;
  Experiment* experiment = options.experiment.get();
  run.start = Clock::now();
  run.first_steps = run.steps();
  const long every = experiment ? experiment->evaluate_every() : options.checkpoint_every;
  const bool exact = experiment || options.reset_every > 0;
  // Checkpoints inside the reports: one learn() call, no boundaries.
  const bool in_reports = !options.checkpoints_split_learning && !exact;
  auto next_multiple = [&](long k) { return (run.steps() / k + 1) * k; };
  long next_checkpoint = next_multiple(every);
  long next_reset = options.reset_every > 0 ? next_multiple(options.reset_every)
                                            : std::numeric_limits<long>::max();
  // A fresh experiment's evaluation of the untrained learner, a checkpoint to resume from.
  if (experiment && !options.resume) {
    evaluate(run);
    save_step_checkpoint(run);
  }
  const ProgressBar bar(options.steps, run.first_steps, options.progress_bar && run.rank == 0);
  double last_score = std::nan(""), last_success = std::nan("");
  // Stopping (Ctrl-C) is agreed by every rank of a data-parallel run.
  bool stopped = false;
  auto stopping = [&] { return run.sync ? stopped : options.stop && options.stop->load(); };
  auto on_progress = [&](const TrainStats& local) {
    TrainStats s = local;
    s.steps += run.offset;
    if (run.sync) {
      stopped = pool_progress(*run.sync, s, run.tally, options.stop && options.stop->load());
    }
    check_finite_losses(s, run.latest);
    write_teacher_log(run);
    if (run.reward) run.reward->update();
    if (experiment && run.rank == 0) experiment->report(s);
    const double elapsed = std::chrono::duration<double>(Clock::now() - run.start).count();
    const EpisodeTally& t = run.tally;
    const double window_score = t.scored > 0 ? t.score_sum / t.scored : std::nan("");
    const double success_rate = t.ended > 0 ? t.successes / t.ended : std::nan("");
    if (t.scored > 0) last_score = window_score;
    if (t.ended > 0) last_success = success_rate;
    run.tally = {};
    if (run.rank == 0) write_progress_row(run, s, elapsed, window_score, success_rate);
    if (options.on_report) options.on_report(s);
    if (in_reports && s.steps >= next_checkpoint && s.steps < options.steps) {
      save_step_checkpoint(run);
      next_checkpoint = next_multiple(every);
    }

    // Only BabyBench scores behaviour.
    bar.show(s.steps, elapsed,
             experiment ? experiment->status()
                        : "return " + csv_cell(s.episodic_return) +
                              (run.by_id ? "" : "  score " + csv_cell(last_score)) +
                              (run.success_slot < 0 ? "" : "  success " + csv_cell(last_success)));
    return true;
  };
  LoopOptions loop{.total_steps = options.steps,
                   .offset = [&] { return run.offset; },
                   .report = on_progress,
                   .at_boundary =
                       [&] {
                         if (run.steps() >= next_reset) {
                           reset_learner(run);
                           next_reset = next_multiple(options.reset_every);
                         }
                         if (!exact || run.steps() >= next_checkpoint) {
                           if (experiment) evaluate(run);
                           save_step_checkpoint(run);
                           next_checkpoint = next_multiple(every);
                         }
                       },
                   .stopping = stopping};
  if (exact)
    loop.next_boundary = [&](long) { return std::min(next_checkpoint, next_reset); };
  else if (!in_reports)
    loop.boundary_every = every;
  const long boundary = run_loop([&run]() -> Learner& { return *run.learner; }, loop);
  // The experiment's last evaluation, at the end of the budget.
  if (experiment && run.steps() >= options.steps && run.last_evaluated != run.steps())
    evaluate(run);
  bar.finish();
  result.steps = run.steps();
  result.seconds = std::chrono::duration<double>(Clock::now() - run.start).count();
  result.steps_per_second = (result.steps - run.first_steps) / std::max(result.seconds, 1e-9);
  return exact || in_reports ? next_checkpoint : boundary;
}

// The end: the final checkpoint and the teacher's state, the ranks' networks compared, then (rank
// 0) the learning curves, the training log's score and the trained policy's evaluation.
void finish(Run& run, long next_checkpoint, TrainResult& result) {
  const TrainOptions& options = run.options;
  result.checkpoint = run.checkpoints / "final.ckpt";
  std::vector<fs::path> files = {run.latest, result.checkpoint};
  const fs::path step = run.checkpoints / ("step_" + std::to_string(run.steps()) + ".ckpt");
  if (run.steps() >= next_checkpoint) files.push_back(step);
  // The teacher's state closes its book before the checkpoint records the book's size (an
  // experiment's evaluations dumped it already).
  if (run.curriculum && !options.experiment) write_teacher_log(run, run.curriculum->env_steps());
  save_checkpoint(run, files);
  if (run.rank == 0 && options.on_checkpoint && files.back() == step) options.on_checkpoint(step);
  VecEnv& vec = *run.training.vec;
  for (int i = 0; i < vec.num_envs(); ++i) vec.env(i).close();
  result.parameter_hash = run.learner->parameter_hash();
  // Data-parallel: every rank must end with the same networks.
  const std::uint64_t hash = result.parameter_hash;
  if (run.sync &&
      !first_disagreement(*run.sync, {{"high", static_cast<double>(hash >> 32)},
                                      {"low", static_cast<double>(hash & 0xffffffffULL)}})
           .empty()) {
    throw UserError(
        "the ranks' parameters differ after training (a learner broke the "
        "data-parallel contract)");
  }
  if (run.rank > 0) return;  // rank 0 draws, scores and evaluates the run
  const bool stopped = options.stop && options.stop->load();
  if (options.experiment) options.experiment->finish(view(run), stopped);
  if (!run.rows.empty())
    plot_curves(run.rows, run.reward != nullptr, run.success_slot >= 0 ? kSuccessColumn : -1,
                run.dir / "plots");
  // The score of the whole run's log (a resumed run's earlier episodes included).
  if (!run.by_id && fs::exists(run.log_file))
    result.training_score = eval::training_score(
        run.config.behavior,
        eval::read_training_log(run.log_file, run.config.behavior, run.training.geom_count));
  if (options.eval_episodes <= 0 || stopped) return;
  Learner* l = run.learner.get();
  // A run by id: the trained policy's whole episodes on a fresh env, acting deterministically
  // from seeds apart from training's (evaluation.json).
  if (run.by_id) {
    std::unique_ptr<envs::Env> env = envs::make_env(run.env_id, options.seed + 1000);
    std::vector<std::uint64_t> seeds;
    for (int k = 0; k < options.eval_episodes; ++k) seeds.push_back(options.seed + 1000 + k);
    result.episodes = run_episodes(
        *env,
        {.act = [l](const envs::ObservationBuffers& obs,
                    std::span<double> action) { l->act(obs, action, /*deterministic=*/true); },
         .new_episode = [l] { l->new_episode(); }},
        seeds);
    env->close();
    nlohmann::ordered_json report = {{"env", run.env_id},
                                     {"algorithm", run.algorithm},
                                     {"steps", l->steps()},
                                     {"policy_actions", "mean"}};
    report.update(episodes_json(result.episodes));
    write_atomically(run.dir / "evaluation.json", report.dump(2) + "\n");
    return;
  }
  // A BabyBench config: the trained policy's evaluation, acting deterministically.
  train::EvaluationOptions eo{.episodes = options.eval_episodes,
                              .duration = options.eval_duration,
                              .render = options.eval_render,
                              .seed = options.seed + 1000,
                              .quiet = true,
                              .policy_actions = "mean"};
  result.evaluation =
      train::evaluate(run.config, eo, [l](const envs::BabyBenchEnv& env, std::span<double> action) {
        l->act(env.observation(), action, /*deterministic=*/true);
      });
  if (options.compare_random) {
    Config baseline = run.config;
    baseline.save_dir = (run.dir / "random_baseline").string();
    eo.render = false;
    result.random_evaluation = train::evaluate(baseline, eo);
  }
}

}  // namespace

TrainResult train(const Config& config, const TrainOptions& options) {
  Run run(config, options);
  check_options(run);
  open_run_folder(run);
  make_curriculum(run);
  make_vector(run);
  make_learner(run);
  open_logs(run);
  TrainResult result;
  const long next_checkpoint = train_loop(run, result);
  finish(run, next_checkpoint, result);
  return result;
}

}  // namespace cradle::train

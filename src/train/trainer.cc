#include "train/trainer.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
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
#include "train/loop.h"
#include "train/task_space.h"

namespace cradle::train {
namespace {

namespace fs = std::filesystem;
// The run drives a learner: checkpoints, run state, stats and intrinsic rewards are learn's.
using namespace cradle::learn;
using Clock = std::chrono::steady_clock;

// Columns of logs/progress.csv, CleanRL's names.
const char* const kColumns[] = {"global_step",
                                "time",
                                "charts/SPS",
                                "charts/episodic_return",
                                "charts/episodic_length",
                                "behaviour/score",
                                "losses/value_loss",
                                "losses/policy_loss",
                                "losses/entropy",
                                "losses/approx_kl",
                                "losses/clip_fraction",
                                "losses/explained_variance",
                                "charts/learning_rate",
                                "losses/qf_loss",
                                "losses/actor_loss",
                                "losses/alpha",
                                "losses/alpha_loss",
                                "losses/qf1_values",
                                "perf/collect_seconds",
                                "perf/update_seconds"};

double loss(const TrainStats& s, const char* name) {
  const auto it = s.losses.find(name);
  return it == s.losses.end() ? std::nan("") : it->second;
}

// Learning curves from progress.csv's rows (matplotlib).
void plot_curves(const std::vector<std::vector<double>>& rows, const fs::path& dir) {
  auto series = [&](int column, const char* label) {
    eval::Series s{.label = label};
    for (const auto& r : rows) {
      if (!std::isnan(r[column])) {
        s.x.push_back(r[0]);
        s.y.push_back(r[column]);
      }
    }
    return s;
  };
  eval::Figures figures;
  figures.add(eval::LinePlot{.title = "Training: episodic return (env + intrinsic)",
                             .x_label = "env steps",
                             .y_label = "return",
                             .series = {series(3, "episodic return")}},
              dir / "learning_curve_return.png");
  figures.add(eval::LinePlot{.title = "Training: behaviour score per episode",
                             .x_label = "env steps",
                             .y_label = "score",
                             .series = {series(5, "behaviour score")}},
              dir / "learning_curve_score.png");
  figures.draw(dir / "figures.json");
}

// Data-parallel: the name of the first value that is not the same on every rank ("" if none).
std::string first_difference(GradSync& sync,
                             const std::vector<std::pair<std::string, double>>& values) {
  std::vector<double> extremes;
  for (const auto& [name, value] : values) extremes.push_back(value);
  for (const auto& [name, value] : values) extremes.push_back(-value);
  sync.all_reduce_max(extremes);
  for (size_t i = 0; i < values.size(); ++i) {
    if (extremes[i] != -extremes[values.size() + i]) return values[i].first;
  }
  return "";
}

// Data-parallel: every rank must run the same command, or the collectives would not pair up.
void check_same_command(GradSync& sync, const std::vector<std::pair<std::string, double>>& values) {
  const std::string differs = first_difference(sync, values);
  if (!differs.empty()) {
    throw UserError("the ranks run different commands (" + differs +
                    " differs): start every rank with the same arguments");
  }
}

// Data-parallel: the ranks' episodes and scores pooled into `stats`; returns whether any rank
// was asked to stop (so that all stop at the same update).
bool pool_progress(GradSync& sync, TrainStats& stats, double& score_sum, int& score_count,
                   bool stop) {
  const bool none = stats.episodes == 0;
  std::vector<double> sums = {static_cast<double>(stats.episodes),
                              none ? 0 : stats.episodes * stats.episodic_return,
                              none ? 0 : stats.episodes * stats.episodic_length,
                              score_sum,
                              static_cast<double>(score_count),
                              stop ? 1.0 : 0.0};
  sync.all_reduce_sum(sums);
  stats.episodes = static_cast<int>(sums[0]);
  stats.episodic_return = sums[0] > 0 ? sums[1] / sums[0] : std::nan("");
  stats.episodic_length = sums[0] > 0 ? sums[2] / sums[0] : std::nan("");
  score_sum = sums[3];
  score_count = static_cast<int>(sums[4]);
  return sums[5] > 0;
}

}  // namespace

namespace {
// Whether a progress.csv holds a row past its header (a run that failed before its first report
// leaves the header only).
bool has_rows(const fs::path& csv) {
  std::ifstream in(csv);
  std::string line;
  return std::getline(in, line) && std::getline(in, line) && !line.empty();
}
}  // namespace

std::string registered_env_id(const std::string& name) {
  // `cradle illustrate`'s short names of the MIMo sample tasks.
  for (const char* short_name : {"reach", "standup", "selfbody", "catch"})
    if (name == short_name) return "mimo/" + name;
  return envs::env_spec(name).id;  // UserError naming the closest ids
}

std::optional<Config> babybench_config(const std::string& name) {
  const envs::EnvSpec spec = envs::env_spec(registered_env_id(name));
  if (spec.family != "babybench") return std::nullopt;
  return spec.config.empty() ? default_config() : load_config(spec.config);
}

TrainResult train(const Config& config, const TrainOptions& options) {
  if (options.steps < 1) throw UserError("--steps must be at least 1");
  if (options.envs < 1) throw UserError("--envs must be at least 1");
  if (options.checkpoint_every < 1) throw UserError("--checkpoint-every must be at least 1");
  // Worker processes: each holds the same number of envs; their envs' teacher and batches would
  // live apart from this process's.
  if (options.procs != 0) {
    if (options.procs < 1) throw UserError("--procs must be at least 1");
    check_procs_split(options.envs, options.procs);
    if (options.async_batch != 0) throw UserError("--procs and --async-batch: give one of them");
    if (!options.task_space.empty()) throw UserError("--procs is not available with --task-space");
  }
  // An env by id (any family but BabyBench's configs, which train as configs) has none of
  // BabyBench's extras: no training log, start randomisation or final evaluation.
  const bool by_id = !options.env.empty();
  const std::string env_id = by_id ? registered_env_id(options.env) : "";
  if (by_id) {
    if (envs::env_spec(env_id).family == "babybench")
      throw UserError("--env " + options.env + " is a BabyBench config: train it as --config " +
                      "(cradle train --env does that for you)");
    if (options.randomize_start || options.compare_random)
      throw UserError(
          "--randomize-start and --compare-random are for BabyBench configs, not --env");
  }
  const fs::path dir = config.save_dir;
  const fs::path checkpoints = dir / "checkpoints";
  const fs::path latest = checkpoints / "latest.ckpt";
  if (options.resume && !fs::exists(latest)) {
    throw UserError("--resume: no checkpoint at '" + latest.string() + "'");
  }
  // A resumed run keeps its algorithm; --hp values override the checkpoint's (those that fix
  // network shapes or observation settings are then refused by load()). The logs are cut back to
  // what the checkpoint knows.
  std::string algorithm = options.algorithm.empty() ? "ppo" : options.algorithm;
  std::map<std::string, std::string> hyperparameters = options.hyperparameters;
  RunState resumed;
  if (options.resume) {
    const CheckpointInfo info = read_checkpoint_info(latest);
    if (!options.algorithm.empty() && options.algorithm != info.algorithm) {
      throw UserError("--resume: the checkpoint is " + info.algorithm + ", not --algo " +
                      options.algorithm + " (leave --algo out to continue it)");
    }
    algorithm = info.algorithm;
    hyperparameters = parse_hyperparameter_text(info.config);
    for (const auto& [name, value] : options.hyperparameters) hyperparameters[name] = value;
    resumed = load_run_state(latest, nullptr);
    // The rewards are part of the task being learned: a resumed run keeps them.
    const std::string wanted =
        options.intrinsic.empty() ? "" : intrinsic::parse_intrinsic(options.intrinsic)->describe();
    if (resumed.intrinsic && *resumed.intrinsic != wanted) {
      throw UserError("--resume: the checkpoint was trained with --intrinsic '" +
                      *resumed.intrinsic + "', not '" + wanted + "' (give --intrinsic '" +
                      *resumed.intrinsic + "' to continue it)");
    }
  }
  // Data-parallel: rank r seeds with seed + r; ranks above 0 log their envs in a folder of their
  // own (continued as they are on resume: the checkpoint counts rank 0's episodes).
  GradSync* sync = distributed(options.sync.get()) ? options.sync.get() : nullptr;
  const int rank = sync ? sync->rank() : 0;
  if (sync && !learn::algorithm_traits(algorithm).data_parallel) {
    throw UserError("--distributed trains " +
                    learn::algorithms_with(&learn::AlgorithmTraits::data_parallel) + ", not " +
                    algorithm);
  }
  // Async collection is the on-policy collector's (docs/async.md).
  if (options.async_batch != 0) {
    if (options.async_batch < 1 || options.async_batch >= options.envs) {
      throw UserError("--async-batch " + std::to_string(options.async_batch) +
                      " must be between 1 and --envs - 1 (" + std::to_string(options.envs - 1) +
                      "): a batch is part of the envs");
    }
    if (!learn::algorithm_traits(algorithm).async_collection) {
      throw UserError("--async-batch is for " +
                      learn::algorithms_with(&learn::AlgorithmTraits::async_collection, "and") +
                      " (their rollout collector), not " + algorithm);
    }
    if (sync) throw UserError("--async-batch is not available with --distributed");
  }
  if (sync) {
    std::string hp_text;
    for (const auto& [name, value] : hyperparameters) hp_text += name + "=" + value + ";";
    check_same_command(
        *sync, {{"--envs", options.envs},
                {"--steps", static_cast<double>(options.steps)},
                {"--checkpoint-every", static_cast<double>(options.checkpoint_every)},
                {"--algo", static_cast<double>(std::hash<std::string>{}(algorithm) % (1L << 40))},
                {"--hp", static_cast<double>(std::hash<std::string>{}(hp_text) % (1L << 40))},
                {"--resume", options.resume ? 1.0 : 0.0},
                {"the checkpoint's step", static_cast<double>(resumed.steps)}});
  }
  // A folder that holds a run (a checkpoint, or progress rows) is never replaced silently:
  // --resume continues it, --overwrite replaces it (its checkpoints, logs and plots go first),
  // anything else is refused. Checked after the options, before anything is written.
  if (!options.resume) {
    std::error_code ec;
    const fs::path progress = dir / "logs" / "progress.csv";
    const bool holds_run = fs::exists(latest, ec) || has_rows(progress);
    if (holds_run && !options.overwrite) {
      throw UserError("'" + dir.string() + "' holds a run (" +
                      (fs::exists(latest, ec) ? latest : progress).string() +
                      "): give --resume to continue it, --overwrite to replace it, or another "
                      "--save-dir");
    }
    if (holds_run && rank == 0) {
      for (const char* sub : {"checkpoints", "logs", "plots", "ranks"}) {
        fs::remove_all(dir / sub, ec);
        if (ec) throw UserError("--overwrite: cannot remove '" + (dir / sub).string() + "'");
      }
    }
  }
  Config env_config = config;
  if (rank > 0) env_config.save_dir = (dir / "ranks" / std::to_string(rank)).string();
  const fs::path log_file = fs::path(env_config.save_dir) / "logs" / "training.jsonl";
  const long kept_episodes =
      options.resume && !by_id
          ? cut_training_log(log_file,
                             rank == 0 ? resumed.episodes : std::numeric_limits<long>::max())
          : -1;

  // A curriculum wraps every env: the teacher sets its reset options before each reset.
  const fs::path teacher_file = fs::path(env_config.save_dir) / "logs" / "teacher.jsonl";
  std::shared_ptr<teach::TeacherController> curriculum;
  EnvWrapper wrap;
  if ((!options.teacher.empty() || options.teacher_factory) && options.task_space.empty())
    throw UserError("--teacher needs --task-space FILE.yml (the parameters it sets)");
  if (!options.teacher.empty() && options.teacher_factory)
    throw UserError("a teacher name and a teacher object: give one of them");
  if (!options.task_space.empty()) {
    // A teacher given by the run needs none named in the file.
    const bool own = !options.teacher.empty() || options.teacher_factory;
    CurriculumSpec spec = load_task_space(options.task_space, /*need_teacher=*/!own);
    if (!options.teacher.empty()) spec.teacher = options.teacher;
    const std::uint64_t teacher_seed = options.seed + rank;  // a teacher per rank
    curriculum = options.teacher_factory
                     ? make_controller(spec, options.teacher_factory(*spec.space, teacher_seed),
                                       teacher_seed)
                     : make_controller(spec, teacher_seed);
    if (options.resume && fs::exists(teacher_file))
      replay_teacher_book(*curriculum, teacher_file, /*periodical=*/false);
    wrap = [curriculum, o = spec.env_options](std::unique_ptr<envs::Env> env) {
      return std::make_unique<CurriculumEnv>(std::move(env), curriculum, o);
    };
  }
  std::optional<JsonlWriter> teacher_log;
  if (curriculum) teacher_log.emplace(teacher_file, options.resume);
  auto write_teacher_log = [&](bool dump) {
    if (!teacher_log) return;
    for (const teach::EpisodeRecord& e : curriculum->take_episodes())
      teacher_log->write(teach::train_line(e));
    if (dump)
      teacher_log->write(teach::dump_line(curriculum->env_steps(), curriculum->teacher_dump()));
    teacher_log->flush();
  };
  // A resumed run's first resets end no episode of this run's log.
  if (by_id) {
    for (const fs::path& logs : {dir / "logs", fs::path(env_config.save_dir) / "logs"}) {
      make_folder(logs, "cannot create");
    }
  }
  TrainingVector training =
      by_id
          ? make_env_training(env_id, options.envs, options.threads, options.seed + rank, wrap,
                              options.async_batch, {}, options.procs)
          : make_babybench_training(env_config, options.envs, options.threads, options.seed + rank,
                                    kept_episodes, wrap, options.async_batch, options.procs);
  std::unique_ptr<VecEnv>& vec = training.vec;
  for (int i = 0; i < vec->num_envs() && options.randomize_start; ++i) {
    vec->env(i).set_reset_options({{"randomize_start", 1}});
  }
  const std::shared_ptr<envs::TrainingLog>& training_log = training.log;
  std::unique_ptr<intrinsic::Composite> reward;
  if (!options.intrinsic.empty()) {
    reward = intrinsic::parse_intrinsic(options.intrinsic);
    reward->bind(*vec);
    // Every learn() resets the vector: no transition spans that reset.
    set_after_reset(*vec, [&reward, &vec] { reward->reset(*vec); });
  }

  // Behaviour score of the episodes that end, seen at the step that ends them (async: the batch,
  // whose slot i is env env_id(i)).
  double score_sum = 0;
  int score_count = 0;
  LearnerOptions lo{.seed = options.seed + rank, .hyperparameters = hyperparameters};
  lo.sync = options.sync;
  lo.update_threads = options.update_threads;
  lo.reward_hook = [&](const VecEnv& env, std::span<const double> actions,
                       std::span<double> rewards) {
    if (reward) reward->compute(env, actions, rewards);
    if (options.reward_hook) options.reward_hook(env, actions, rewards);
    for (int i = 0; i < env.num_envs(); ++i) {
      if (env.terminated()[i] || env.truncated()[i]) {
        const double s = env.env(i).score();
        if (!std::isnan(s)) {
          score_sum += s;
          ++score_count;
        }
      }
    }
  };
  std::unique_ptr<Learner> learner = learn::make_learner(algorithm, *vec, lo);
  // SPDL values its tasks with the student's value function.
  if (curriculum)
    curriculum->teacher().set_value_estimator(learner_value_estimator(
        [&learner]() -> Learner& { return *learner; }, vec->observation_space()));
  if (options.resume) {
    learner->load(latest);
    load_run_state(latest, reward.get());
  }

  std::error_code ec;
  fs::create_directories(checkpoints, ec);
  // A checkpoint is an episode boundary: every env's episode is recorded (cut short) and the log
  // flushed, so the checkpoint's episode count is the log's, and the next learn() starts fresh
  // episodes exactly as a resumed run does.
  auto save_checkpoint = [&](const std::vector<fs::path>& files) {
    training.end_episodes();
    if (training_log) training_log->flush();
    const RunState run{.steps = learner->steps(),
                       .episodes = training_log ? training_log->episodes() : 0,
                       .intrinsic = reward ? reward->describe() : ""};
    if (rank > 0) return;  // rank 0 writes the run's checkpoints
    for (const fs::path& file : files) save_run_checkpoint(file, *learner, reward.get(), run);
  };

  // progress.csv: continued on resume, cut back to the checkpoint's step (later rows and a torn
  // line kept aside); another version's file is kept beside a new one.
  // run.json: what this run is (a fresh run writes it; a resumed one keeps it).
  if (rank == 0 && !options.resume) {
    nlohmann::ordered_json run = {{"cradle_version", CRADLE_VERSION},
                                  {"env", by_id ? env_id : "babybench config"},
                                  {"family", by_id ? envs::env_spec(env_id).family : "babybench"},
                                  {"algorithm", algorithm},
                                  {"seed", options.seed},
                                  {"steps", options.steps},
                                  {"envs", options.envs},
                                  {"checkpoint_every", options.checkpoint_every},
                                  {"intrinsic", reward ? reward->describe() : ""},
                                  {"hyperparameters", hyperparameters},
                                  {"task_space", options.task_space},
                                  {"teacher", options.teacher},
                                  {"world_size", sync ? sync->world_size() : 1}};
    if (!by_id) run["config"] = to_json(config);
    write_atomically(dir / "run.json", run.dump(2) + "\n");
  }
  const fs::path csv_file = dir / "logs" / "progress.csv";
  std::string header;
  // The learner's own report keys follow the common columns (SaMI's: its SaNCE loss and weight).
  std::vector<std::string> columns(std::begin(kColumns), std::end(kColumns));
  const std::vector<std::string> extra = extra_report_keys(algorithm);
  for (const std::string& key : extra) columns.push_back("losses/" + key);
  for (size_t c = 0; c < columns.size(); ++c) header += (c ? "," : "") + columns[c];
  ProgressCut cut;
  if (options.resume && rank == 0) cut = cut_progress(csv_file, header, resumed.steps);
  if (!cut.kept_aside.empty())
    std::cerr << "progress.csv rows kept aside in " << cut.kept_aside.string() << "\n";
  // Rank 0 writes progress.csv; the others' stream writes nowhere.
  std::ofstream csv;
  if (rank == 0) csv.open(csv_file, cut.append ? std::ios::app : std::ios::trunc);
  if (rank == 0 && !csv) throw UserError("cannot write '" + csv_file.string() + "'");
  if (!cut.append) csv << header << "\n";
  std::vector<std::vector<double>> rows = std::move(cut.rows);
  for (auto& row : rows) row.resize(columns.size(), std::nan(""));

  const auto start = Clock::now();
  const long first_step = learner->steps();
  const ProgressBar bar(options.steps, first_step, options.progress_bar && rank == 0);
  double last_score = std::nan("");
  // Stopping (Ctrl-C) is agreed by every rank of a data-parallel run.
  bool stopped = false;
  auto stopping = [&] { return sync ? stopped : options.stop && options.stop->load(); };
  auto on_progress = [&](const TrainStats& local) {
    TrainStats s = local;
    if (sync) {
      stopped =
          pool_progress(*sync, s, score_sum, score_count, options.stop && options.stop->load());
    }
    check_finite_losses(s, latest);
    write_teacher_log(false);
    if (reward) reward->update();
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    if (score_count > 0) last_score = score_sum / score_count;
    const double window_score = score_count > 0 ? score_sum / score_count : std::nan("");
    score_sum = 0;
    score_count = 0;
    std::vector<double> row = {static_cast<double>(s.steps),
                               elapsed,
                               s.sps,
                               s.episodic_return,
                               s.episodic_length,
                               window_score,
                               loss(s, "value_loss"),
                               loss(s, "policy_loss"),
                               loss(s, "entropy"),
                               loss(s, "approx_kl"),
                               loss(s, "clip_fraction"),
                               loss(s, "explained_variance"),
                               loss(s, "learning_rate"),
                               loss(s, "qf_loss"),
                               loss(s, "actor_loss"),
                               loss(s, "alpha"),
                               loss(s, "alpha_loss"),
                               loss(s, "qf1_values"),
                               loss(s, "collect_seconds"),
                               loss(s, "update_seconds")};
    for (const std::string& key : extra) row.push_back(loss(s, key.c_str()));
    for (size_t c = 0; c < row.size(); ++c) csv << (c ? "," : "") << csv_cell(row[c]);
    csv << "\n";
    csv.flush();
    if (rank == 0 && !csv) throw UserError("cannot write '" + csv_file.string() + "'");
    rows.push_back(std::move(row));
    if (options.on_report) options.on_report(s);

    // Only BabyBench scores behaviour.
    bar.show(
        s.steps, elapsed,
        "return " + csv_cell(s.episodic_return) + (by_id ? "" : "  score " + csv_cell(last_score)));
    return true;
  };
  // Learning stops at each checkpoint (an episode boundary) and continues in a new learn() call.
  const long next_checkpoint = run_loop(
      *learner,
      {.total_steps = options.steps,
       .boundary_every = options.checkpoint_every,
       .report = on_progress,
       .at_boundary =
           [&] {
             save_checkpoint(
                 {checkpoints / ("step_" + std::to_string(learner->steps()) + ".ckpt"), latest});
           },
       .stopping = stopping});
  bar.finish();

  TrainResult result;
  result.steps = learner->steps();
  result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  result.steps_per_second = (result.steps - first_step) / std::max(result.seconds, 1e-9);
  result.checkpoint = checkpoints / "final.ckpt";
  std::vector<fs::path> files = {latest, result.checkpoint};
  if (learner->steps() >= next_checkpoint) {
    files.push_back(checkpoints / ("step_" + std::to_string(learner->steps()) + ".ckpt"));
  }
  save_checkpoint(files);
  write_teacher_log(true);
  for (int i = 0; i < vec->num_envs(); ++i) vec->env(i).close();
  result.parameter_hash = learner->parameter_hash();
  // Data-parallel: every rank must end with the same networks.
  const std::uint64_t hash = result.parameter_hash;
  if (sync && !first_difference(*sync, {{"high", static_cast<double>(hash >> 32)},
                                        {"low", static_cast<double>(hash & 0xffffffffULL)}})
                   .empty()) {
    throw UserError(
        "the ranks' parameters differ after training (a learner broke the "
        "data-parallel contract)");
  }
  if (rank > 0) return result;  // rank 0 draws, scores and evaluates the run
  if (!rows.empty()) plot_curves(rows, dir / "plots");
  // The score of the whole run's log (a resumed run's earlier episodes included).
  if (!by_id && fs::exists(log_file))
    result.training_score = eval::training_score(
        config.behavior, eval::read_training_log(log_file, config.behavior, training.geom_count));

  // A run by id: the trained policy's whole episodes on a fresh env, acting deterministically
  // from seeds apart from training's (evaluation.json).
  if (by_id && options.eval_episodes > 0 && !(options.stop && options.stop->load())) {
    std::unique_ptr<envs::Env> env = envs::make_env(env_id, options.seed + 1000);
    std::vector<std::uint64_t> seeds;
    for (int k = 0; k < options.eval_episodes; ++k) seeds.push_back(options.seed + 1000 + k);
    Learner* l = learner.get();
    result.episodes = run_episodes(
        *env,
        {.act = [l](const envs::ObservationBuffers& obs,
                    std::span<double> action) { l->act(obs, action, /*deterministic=*/true); },
         .new_episode = [l] { l->new_episode(); }},
        seeds);
    env->close();
    nlohmann::ordered_json report = {{"env", env_id},
                                     {"algorithm", algorithm},
                                     {"steps", learner->steps()},
                                     {"policy_actions", "mean"}};
    report.update(episodes_json(result.episodes));
    write_atomically(dir / "evaluation.json", report.dump(2) + "\n");
  }

  // The trained policy's evaluation, acting deterministically.
  if (!by_id && options.eval_episodes > 0 && !(options.stop && options.stop->load())) {
    train::EvaluationOptions eo{.episodes = options.eval_episodes,
                                .duration = options.eval_duration,
                                .render = options.eval_render,
                                .seed = options.seed + 1000,
                                .quiet = true,
                                .policy_actions = "mean"};
    Learner* l = learner.get();
    result.evaluation =
        train::evaluate(config, eo, [l](const envs::BabyBenchEnv& env, std::span<double> action) {
          l->act(env.observation(), action, /*deterministic=*/true);
        });
    if (options.compare_random) {
      Config baseline = config;
      baseline.save_dir = (dir / "random_baseline").string();
      eo.render = false;
      result.random_evaluation = train::evaluate(baseline, eo);
    }
  }
  return result;
}

train::Policy load_policy(const Config& config, const std::filesystem::path& checkpoint,
                          bool sampled) {
  if (!fs::exists(checkpoint)) {
    throw UserError("policy checkpoint '" + checkpoint.string() + "' does not exist");
  }
  const CheckpointInfo info = learn::read_checkpoint_info(checkpoint);
  // A one-env vector of the config gives the learner its spaces; it is kept alive by the policy.
  std::shared_ptr<VecEnv> vec = make_babybench_vec_env(config, 1, 1, /*training=*/false, 0);
  LearnerOptions lo{.hyperparameters = learn::parse_hyperparameter_text(info.config)};
  std::shared_ptr<Learner> learner = learn::make_learner(info.algorithm, *vec, lo);
  learner->load(checkpoint);
  return [vec, learner, sampled](const envs::BabyBenchEnv& env, std::span<double> action) {
    learner->act(env.observation(), action, /*deterministic=*/!sampled);
  };
}

}  // namespace cradle::train

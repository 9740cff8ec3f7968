#include "train/tma_student.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

#include "core/config.h"
#include "core/error.h"
#include "core/sealed_file.h"
#include "envs/registry.h"
#include "envs/tma/tma_env.h"
#include "learn/hyperparams.h"
#include "learn/run_files.h"
#include "tma/cppn.h"
#include "train/episodes.h"
#include "train/experiment.h"
#include "train/loop.h"
#include "train/run_json.h"
#include "train/task_space.h"
#include "train/trainer.h"

namespace cradle::train {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

const char* const kProgressHeader =
    "evaluation,env_steps,episodes,wall_s,sps,mean_test_return,std_test_return,pct_mastered,"
    "mean_train_return,gradient_steps,teacher_s";
const char* const kTestHeader = "evaluation,env_steps,task_index,return,mastered";
// Arguments a resumed run may change.
const char* const kResumable[] = {"nb_env_steps", "test_every", "resume", "out", "progress_bar"};

// The run's wall time at its last evaluation: progress.csv's last wall_s (0 without one).
double last_wall(const fs::path& progress) {
  std::ifstream in(progress);
  std::string line, last;
  if (!std::getline(in, line) || line != kProgressHeader) return 0;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  std::istringstream row(last);
  std::vector<std::string> cells;
  for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
  if (cells.size() < 4) return 0;
  char* end = nullptr;
  const double wall = std::strtod(cells[3].c_str(), &end);
  return end != cells[3].c_str() && std::isfinite(wall) && wall >= 0 ? wall : 0;
}

// The benchmark's evaluations as the run's experiment: every test task once with the
// deterministic policy at each multiple of test_every (and before training, and at the end), one
// row of progress.csv per evaluation, one row of test_returns.csv per test episode, summary.json
// at the end.
class TmaEvaluations : public Experiment {
 public:
  TmaEvaluations(long test_every, std::uint64_t seed, double success_threshold,
                 std::vector<std::string> dim_names, std::vector<teach::Task> test_set,
                 std::unique_ptr<envs::Env> test_env)
      : test_every_(test_every),
        seed_(seed),
        success_threshold_(success_threshold),
        names_(std::move(dim_names)),
        test_set_(std::move(test_set)),
        test_env_(std::move(test_env)) {}

  long evaluate_every() const override { return test_every_; }
  std::vector<std::string> files() const override {
    return {"run.json", "progress.csv", "test_returns.csv", "test_set.csv", "summary.json"};
  }
  std::vector<std::string> logs() const override { return {"progress.csv", "test_returns.csv"}; }

  void open(const fs::path& dir, const nlohmann::json* resumed) override {
    dir_ = dir;
    // test_set.csv: the tasks in evaluation order.
    std::ostringstream csv;
    csv << "task_index";
    for (const std::string& n : names_) csv << "," << n;
    csv << "\n";
    for (std::size_t i = 0; i < test_set_.size(); ++i) {
      csv << i;
      for (float v : test_set_[i]) csv << "," << csv_cell(v);
      csv << "\n";
    }
    write_atomically(dir / "test_set.csv", csv.str());
    if (resumed) {
      const RunJson state("the checkpoint's evaluation state", *resumed,
                          "the run state of a `cradle tma run` checkpoint");
      evaluation_ = static_cast<int>(std::min(state.count("evaluations"), 1L << 30));
      // A checkpoint of an earlier version has no last evaluation (nor, stopped before its
      // first evaluation, one that resumed such a checkpoint): NaN until the next.
      if (state.has("pct_mastered") && state.json()["pct_mastered"].is_number()) {
        last_mean_test_return_ = state.number("mean_test_return");
        last_pct_mastered_ = state.number("pct_mastered");
      } else {
        last_mean_test_return_ = last_pct_mastered_ = std::nan("");
      }
      resumed_ = true;
      wall_before_ = last_wall(dir / "progress.csv");
    }
    progress_ = learn::continue_log(dir / "progress.csv", kProgressHeader, resumed != nullptr);
    test_csv_ = learn::continue_log(dir / "test_returns.csv", kTestHeader, resumed != nullptr);
    start_ = Clock::now();
  }

  void report(const learn::TrainStats& s) override {
    // SAC's update counter (per learner; a resumed one counts from its first report).
    const auto it = s.losses.find("updates");
    if (it == s.losses.end()) return;
    if (std::isnan(updates_done_)) updates_done_ = 0;
    if (std::isnan(updates_seen_)) updates_seen_ = resumed_ ? it->second : 0;
    updates_done_ += it->second - updates_seen_;
    updates_seen_ = it->second;
  }
  void learner_replaced() override { updates_seen_ = 0; }
  // The last evaluation's in the run's progress rows.
  std::vector<std::string> progress_columns() const override {
    return {"eval/mean_test_return", "eval/pct_mastered"};
  }
  std::vector<double> progress_values() const override {
    return {last_mean_test_return_, last_pct_mastered_};
  }
  void booked(const teach::EpisodeRecord& e) override {
    train_return_sum_ += e.ret;
    ++train_returns_;
  }

  void evaluate(const RunView& run) override {
    const auto eval_start = Clock::now();
    teach::TeacherController& controller = *run.curriculum;
    std::vector<teach::Task> tasks;
    std::vector<std::uint64_t> seeds;
    for (int i = 0; i < controller.test_set_size(); ++i) {
      tasks.push_back(controller.next_test_task());
      seeds.push_back(seed_ * 1000003 + 100000 + static_cast<std::uint64_t>(i));
    }
    learn::Learner* student = &run.learner;
    const std::vector<EpisodeOutcome> episodes = run_episodes(
        *test_env_,
        {.act = [student](const envs::ObservationBuffers& obs,
                          std::span<double> action) { student->act(obs, action, true); }},
        seeds, 0, nullptr, [&](int i, envs::Env& e) {
          envs::ResetOptions task_options;
          for (std::size_t d = 0; d < names_.size(); ++d) task_options[names_[d]] = tasks[i][d];
          e.set_reset_options(task_options);
        });
    double mean = 0, var = 0;
    int mastered = 0;
    for (std::size_t i = 0; i < episodes.size(); ++i) {
      const double ret = episodes[i].episode_return;
      controller.record_test_episode(ret, episodes[i].length);
      test_csv_ << evaluation_ << "," << run.steps << "," << i << "," << csv_cell(ret) << ","
                << (ret > success_threshold_ ? 1 : 0) << "\n";
      mean += ret / episodes.size();
      mastered += ret > success_threshold_;
    }
    for (const EpisodeOutcome& e : episodes)
      var += (e.episode_return - mean) * (e.episode_return - mean) / episodes.size();
    const double pct = 100.0 * mastered / episodes.size();
    eval_s_ += std::chrono::duration<double>(Clock::now() - eval_start).count();
    progress_ << evaluation_ << "," << run.steps << "," << controller.episodes() << ","
              << csv_cell(wall()) << ","
              << csv_cell((run.steps - run.first_steps) / std::max(run.seconds, 1e-9)) << ","
              << csv_cell(mean) << "," << csv_cell(std::sqrt(var)) << "," << csv_cell(pct) << ","
              << csv_cell(train_returns_ ? train_return_sum_ / train_returns_ : std::nan("")) << ","
              << csv_cell(updates_done_) << "," << csv_cell(run.teacher_seconds) << "\n";
    train_return_sum_ = 0;
    train_returns_ = 0;
    progress_.flush();
    test_csv_.flush();
    if (!progress_ || !test_csv_)
      throw UserError("cannot write the run's logs in '" + dir_.string() + "'");
    last_pct_mastered_ = pct;
    last_mean_test_return_ = mean;
    ++evaluations_;
    ++evaluation_;
  }

  // No time in it: a checkpoint's bytes are the same in every run of the same command.
  nlohmann::json state() const override {
    return {{"evaluations", evaluation_},
            {"mean_test_return", last_mean_test_return_},
            {"pct_mastered", last_pct_mastered_}};
  }
  std::string status() const override { return "mastered " + csv_cell(last_pct_mastered_) + "%"; }

  void finish(const RunView& run, bool stopped) override {
    const double wall_s = std::chrono::duration<double>(Clock::now() - start_).count();
    summary_ = {{"env_steps", run.steps},
                {"episodes", run.curriculum->episodes()},
                {"evaluations", evaluations_},
                {"wall_s", wall_s},
                {"env_steps_per_s", (run.steps - run.first_steps) / std::max(wall_s, 1e-9)},
                {"gradient_steps", updates_done_},
                {"gradient_steps_per_s", updates_done_ / std::max(wall_s, 1e-9)},
                {"teacher_s", run.teacher_seconds},
                {"teacher_share", run.teacher_seconds / std::max(wall_s, 1e-9)},
                {"eval_s", eval_s_},
                {"pct_mastered", last_pct_mastered_},
                {"stopped", stopped},
                {"checkpoint_env_steps", run.steps}};
    // NaN (PPO's gradient steps) is written as null.
    write_atomically(dir_ / "summary.json", summary_.dump(2) + "\n");
  }

  const nlohmann::ordered_json& summary() const { return summary_; }

 private:
  // The run's wall time: earlier processes' and this one's.
  double wall() const {
    return wall_before_ + std::chrono::duration<double>(Clock::now() - start_).count();
  }

  long test_every_;
  std::uint64_t seed_;
  double success_threshold_;
  std::vector<std::string> names_;
  std::vector<teach::Task> test_set_;
  std::unique_ptr<envs::Env> test_env_;
  fs::path dir_;
  std::ofstream progress_, test_csv_;
  int evaluation_ = 0, evaluations_ = 0;
  double wall_before_ = 0;
  bool resumed_ = false;
  Clock::time_point start_ = Clock::now();
  double train_return_sum_ = 0;
  long train_returns_ = 0;
  double updates_done_ = std::nan(""), updates_seen_ = std::nan("");
  double eval_s_ = 0, last_pct_mastered_ = 0, last_mean_test_return_ = std::nan("");
  nlohmann::ordered_json summary_;
};

}  // namespace

StudentEnv tma_student_env(const tma::TmaOptions& options, const TmaBenchmark& benchmark) {
  const tma::TmaEnv probe(options);  // refuses an unknown embodiment or option now
  const bool stumps = options.env == tma::EnvId::kStumpTracks;
  using J = nlohmann::ordered_json;
  J bounds;
  if (stumps) {
    bounds["stump_height"] = {benchmark.min_stump_h, benchmark.max_stump_h};
    bounds["obstacle_spacing"] = {0.0, benchmark.max_obstacle_spacing};
  } else {
    // The env's task parameters, the values of a vector parameter (input_vector_k) grouped.
    for (const envs::TaskParameter& p :
         envs::tma_task_parameters(options.env, options.input_cppn_dim)) {
      if (p.name.starts_with("input_vector_")) {
        bounds["input_vector"].push_back({p.low, p.high});
      } else {
        bounds[p.name] = {p.low, p.high};
      }
    }
  }
  StudentEnv env{.space = teach::TaskSpace::from_json(bounds),
                 .reward_lb = -150,
                 .reward_ub = stumps ? 350.0 : 360.0};
  // Stump Tracks' easy corner (high expert knowledge): no stumps, the largest spacing.
  if (stumps) {
    const float h = static_cast<float>(benchmark.max_stump_h - benchmark.min_stump_h);
    const float sp = static_cast<float>(benchmark.max_obstacle_spacing);
    env.initial_dist =
        teach::DiagGaussian{.mean = {0.f, sp}, .variance = {0.01f * h * h, 0.01f * sp * sp}};
  }
  if (!benchmark.test_set.empty()) {
    env.test_set =
        teach::read_test_set_csv(tma::data_dir() / (benchmark.test_set + ".csv"), env.space);
  }
  return env;
}

std::map<std::string, std::string> student_preset(const std::string& student, long total_steps) {
  // SpinningUp SAC as TeachMyAgent runs it (spec §4.1).
  if (student == "sac") {
    return {{"pi_layers", "400,300"},
            {"qf_layers", "400,300"},
            {"activation", "relu"},
            {"batch_size", "1000"},
            {"ent_coef", "0.005"},
            {"learning_rate", "0.001"},
            {"buffer_size", std::to_string(std::clamp(total_steps, 1L, 2'000'000L))},
            {"learning_starts", "10000"},
            {"tau", "0.005"},
            {"gamma", "0.99"},
            {"episode_train_freq", "10"},
            {"report_every", "1000"}};
  }
  // Baselines ppo2 as criterion 5 runs it (spec §4.2).
  if (student == "ppo") {
    return {{"shared_layers", "400,300"},
            {"pi_layers", ""},
            {"vf_layers", ""},
            {"activation", "tanh"},
            {"ortho_init", "true"},
            {"log_std_init", "0"},
            {"n_steps", "20000"},
            {"batch_size", "1000"},
            {"n_epochs", "5"},
            {"learning_rate", "0.0003"},
            {"clip_range", "0.2"},
            {"gae_lambda", "0.95"},
            {"gamma", "0.99"},
            {"vf_coef", "0.5"},
            {"ent_coef", "0"},
            {"max_grad_norm", "0.5"},
            {"normalize_observations", "true"},
            {"clip_observations", "10"},
            {"normalize_returns", "true"}};
  }
  throw UserError("--student '" + student + "' (expected sac or ppo)");
}

TmaRun run_tma(const TmaRunArguments& a) {
  // --steps is the budget in env steps; recorded as the reference's millions.
  const double millions = a.steps > 0 ? static_cast<double>(a.steps) / 1e6 : a.nb_env_steps;
  if (a.steps < 0 || a.steps > static_cast<long>(kTmaMaxMillions * 1e6)) {
    throw UserError("--steps " + std::to_string(a.steps) + " (expected 1 to " +
                    std::to_string(static_cast<long>(kTmaMaxMillions * 1e6)) + " env steps)");
  }
  if (!(millions > 0) || !std::isfinite(millions)) {
    throw UserError("--nb_env_steps " + std::to_string(millions) +
                    " (expected a positive number of millions)");
  }
  // The unit is millions (run.py's): 20000 would be 2e10 steps, weeks of a cluster.
  if (millions > kTmaMaxMillions) {
    char text[160];
    std::snprintf(text, sizeof text,
                  "--nb_env_steps %g is in millions of env steps (%.3g steps): expected at most "
                  "%g (for %g steps give %g)",
                  millions, millions * 1e6, kTmaMaxMillions, millions, millions / 1e6);
    throw UserError(text);
  }
  const long total_steps = a.steps > 0 ? a.steps : std::lround(millions * 1e6);
  if (total_steps < 1) throw UserError("--nb_env_steps must give at least 1 env step");
  if (a.test_every < 1) throw UserError("--test_every must be at least 1");
  if (a.nb_test_episodes < 1) throw UserError("--nb_test_episodes must be at least 1");
  if (a.reset_frequency < 0) throw UserError("--reset_frequency must be >= 0 (0: never)");
  if (a.resume && a.overwrite) throw UserError("--resume and --overwrite: give one of them");
  const nlohmann::json teacher_params = teach::parse_teacher_params(a.teacher_params);
  std::map<std::string, std::string> user_hp = learn::parse_hyperparameter_flags(a.hp);
  // learning_rate with --lr would keep only one value, silently.
  if (a.lr != 0 && !user_hp.emplace("learning_rate", std::to_string(a.lr)).second)
    throw UserError("--hp learning_rate is given twice (also by --lr); expected each name once");
  // The reference preset under the user's values.
  std::map<std::string, std::string> hyperparameters = student_preset(a.student, total_steps);
  for (const auto& [k, v] : user_hp) hyperparameters[k] = v;
  const fs::path out = a.out.empty() ? fs::path("tma_runs") / a.exp_name /
                                           (a.exp_name + "_s" + std::to_string(a.seed))
                                     : fs::path(a.out);
  {
    std::error_code ec;
    if (fs::exists(out, ec) && !fs::is_directory(out, ec))
      throw UserError("--out '" + out.string() + "' is a file; expected a run folder");
  }
  nlohmann::ordered_json arguments = {
      {"exp_name", a.exp_name},
      {"env", a.env},
      {"embodiment", a.body},
      {"student", a.student},
      {"teacher", a.teacher},
      {"teacher_params", teacher_params},
      {"allow_expert_knowledge", a.expert_knowledge},
      {"nb_env_steps", millions},
      {"test_set", a.test_set},
      {"nb_test_episodes", a.nb_test_episodes},
      {"seed", a.seed},
      {"keep_periodical_task_samples", a.keep_periodical_task_samples},
      {"shuffle_dimensions", a.shuffle_dimensions},
      {"scale_reward", a.scale_reward},
      {"test_every", a.test_every},
      {"reset_frequency", a.reset_frequency},
      {"min_stump_h", a.min_stump_h},
      {"max_stump_h", a.max_stump_h},
      {"max_obstacle_spacing", a.max_obstacle_spacing},
      {"lr", a.lr},
      {"hp", a.hp},
      {"out", out.string()},
      {"resume", a.resume}};
  // Recorded when given, or when resuming a run that has them (so that leaving them out is
  // refused by name); runs without them resume as before.
  nlohmann::json env_options = nlohmann::json::object();
  for (const auto& [name, value] : a.env_options) env_options[name] = value;
  if (!env_options.empty()) arguments["env_options"] = env_options;

  // A resume gives the run's arguments again (but the resumable ones); every file checked before
  // anything is cut or changed.
  if (a.resume) {
    std::error_code ec;
    if (fs::exists(out / "checkpoints" / "latest.json", ec)) {
      throw UserError("--resume: '" + out.string() +
                      "' was written by an earlier Cradle (checkpoints/latest.json): continue it "
                      "with that version, or give --overwrite to start it anew");
    }
    if (!fs::exists(out / "checkpoints" / "latest.ckpt", ec))
      throw UserError("--resume: no checkpoint in '" + (out / "checkpoints").string() + "'");
    const RunJson saved(out / "run.json", "the run.json of a `cradle tma run` run");
    const RunJson saved_arguments = saved.object("arguments");
    if (saved_arguments.has("env_options")) arguments["env_options"] = env_options;
    for (const auto& [key, value] : arguments.items()) {
      if (std::find(std::begin(kResumable), std::end(kResumable), key) != std::end(kResumable))
        continue;
      const nlohmann::json before = saved_arguments.json().value(key, nlohmann::json());
      if (before != nlohmann::json::parse(value.dump())) {
        throw UserError("--resume: --" + key + " is " + value.dump() + " but the run had " +
                        before.dump() + " (give the run's arguments again)");
      }
    }
  }

  // The benchmark's half: the env with its options, its facts and the curriculum over them.
  tma::TmaOptions options{.env = tma::parse_env_id(a.env), .body = a.body};
  for (const auto& [name, value] : a.env_options) tma::set_option(options, name, value);
  const StudentEnv env = tma_student_env(options, {.min_stump_h = a.min_stump_h,
                                                   .max_stump_h = a.max_stump_h,
                                                   .max_obstacle_spacing = a.max_obstacle_spacing,
                                                   .test_set = a.test_set});
  CurriculumSpec curriculum{.teacher = a.teacher,
                            .space = env.space,
                            .teacher_params = teacher_params,
                            .expert_knowledge = a.expert_knowledge,
                            .env_options = {.success_threshold = env.success_threshold},
                            .reward_lb = env.reward_lb,
                            .reward_ub = env.reward_ub,
                            .scale_reward = a.scale_reward,
                            .initial_dist = env.initial_dist,
                            .shuffle_dimensions = a.shuffle_dimensions,
                            .keep_periodical_task_samples = a.keep_periodical_task_samples,
                            .test_set = env.test_set.empty()
                                            ? teach::default_test_set(env.space, a.nb_test_episodes)
                                            : env.test_set};
  const std::string id =
      std::string(options.env == tma::EnvId::kParkour ? "tma/parkour:" : "tma/stump-tracks:") +
      a.body;
  envs::EnvOptions maker_options(a.env_options.begin(), a.env_options.end());
  // The test env: one of the same maker, apart from training's.
  auto evaluations = std::make_shared<TmaEvaluations>(
      a.test_every, a.seed, env.success_threshold, env.space.dim_names(), curriculum.test_set,
      envs::env_maker(id, maker_options)(0, a.seed));

  nlohmann::ordered_json run_json;
  run_json["arguments"] = arguments;
  run_json["student"] = a.student;
  run_json["expert_knowledge"] = a.expert_knowledge;
  run_json["teacher_params"] = teacher_params;
  run_json["env_steps"] = total_steps;
  run_json["test_every"] = a.test_every;
  run_json["shuffle_dimensions"] = a.shuffle_dimensions;
  run_json["scale_reward"] = a.scale_reward;
  run_json["reset_frequency"] = a.reset_frequency;
  run_json["keep_periodical_task_samples"] = a.keep_periodical_task_samples;
  run_json["reward_bounds"] = {env.reward_lb, env.reward_ub};
  run_json["success_threshold"] = env.success_threshold;
  run_json["bounds"] = env.space.bounds_json();
  run_json["commit"] = a.commit;

  // One training env, as the reference, through the one run.
  TrainOptions train_options{.env = id,
                             .algorithm = a.student,
                             .intrinsic = "",
                             .steps = total_steps,
                             .envs = 1,
                             .seed = a.seed,
                             .resume = a.resume,
                             .overwrite = a.overwrite,
                             .checkpoint_every = a.test_every,
                             .hyperparameters = hyperparameters,
                             .eval_episodes = 0,
                             .progress_bar = a.progress_bar,
                             .teacher = a.teacher,
                             .curriculum = curriculum,
                             .stop = a.stop,
                             .experiment = evaluations,
                             .reset_every = a.reset_frequency,
                             .keep_step_checkpoints = false,
                             .env_options = maker_options,
                             .run_json = run_json};
  train_options.sync = a.sync;
  Config config = default_config();
  config.save_dir = out.string();
  const TrainResult trained = train(config, train_options);
  return {.out = out,
          .summary = evaluations->summary(),
          .stopped = trained.steps < total_steps,
          .parameter_hash = trained.parameter_hash};
}

}  // namespace cradle::train

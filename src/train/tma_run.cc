#include "train/tma_run.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <sstream>

#include "core/error.h"
#include "core/folders.h"
#include "core/jsonl.h"
#include "core/sealed_file.h"
#include "envs/tma/tma_env.h"
#include "learn/hyperparams.h"
#include "learn/learner.h"
#include "learn/registry.h"
#include "learn/run_files.h"
#include "learn/vector_env.h"
#include "tma/cppn.h"
#include "train/curriculum_env.h"
#include "train/episodes.h"
#include "train/loop.h"
#include "train/run_json.h"
#include "train/task_space.h"

namespace cradle::train {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

const char* const kProgressHeader =
    "evaluation,env_steps,episodes,wall_s,sps,mean_test_return,std_test_return,pct_mastered,"
    "mean_train_return,gradient_steps,teacher_s";
const char* const kTestHeader = "evaluation,env_steps,task_index,return,mastered";
// The files a checkpoint records the size of (cut back to it on resume).
const char* const kLogs[] = {"progress.csv", "test_returns.csv", "teacher.jsonl"};
// Arguments a resumed run may change.
const char* const kResumable[] = {"nb_env_steps", "test_every", "resume", "out", "progress_bar"};

// Splits a CSV line of plain cells (our logs hold numbers and names, never quotes).
std::vector<std::string> split_cells(const std::string& line) {
  std::vector<std::string> cells;
  std::size_t at = 0;
  for (;;) {
    const std::size_t comma = line.find(',', at);
    cells.push_back(line.substr(at, comma == std::string::npos ? comma : comma - at));
    if (comma == std::string::npos) return cells;
    at = comma + 1;
  }
}

// A log written by a binary with other columns (an older one: fewer) under the current `header`.
// Each row's cells move under their column's name, the columns the old binary lacked stay empty,
// and the file is rewritten in place, so one CSV holds the whole run and its evaluation numbering
// goes on. When a column of the old file has no place in the current header, the old file is also
// kept whole as <stem>.before-resume[-k]<ext>. A row that does not fit its header (a damaged file)
// cannot be carried over: the file is then kept whole aside and a fresh one begins. Returns
// whether the file still needs its header (kept aside or missing); prints one line when it
// changed anything.
bool adopt_header(const fs::path& file, const std::string& header) {
  std::ifstream in(file);
  std::string first;
  if (!in || !std::getline(in, first)) return true;
  if (first == header) return false;
  const std::vector<std::string> now = split_cells(header), old = split_cells(first);
  std::vector<int> where(old.size(), -1);  // each old column's index in the current header
  bool dropped = false;
  for (std::size_t c = 0; c < old.size(); ++c) {
    const auto it = std::find(now.begin(), now.end(), old[c]);
    if (it == now.end())
      dropped = true;
    else
      where[c] = static_cast<int>(it - now.begin());
  }
  std::ostringstream text;
  text << header << "\n";
  bool fits = true;
  for (std::string line; std::getline(in, line);) {
    const std::vector<std::string> cells = split_cells(line);
    if (cells.size() != old.size()) {
      fits = false;
      break;
    }
    std::vector<std::string> row(now.size());
    for (std::size_t c = 0; c < cells.size(); ++c)
      if (where[c] >= 0) row[where[c]] = cells[c];
    for (std::size_t c = 0; c < row.size(); ++c) text << (c ? "," : "") << row[c];
    text << "\n";
  }
  in.close();
  const std::string name = file.filename().string();
  if (!fits) {
    const fs::path kept = learn::keep_aside_before_resume(file);
    std::cerr << name << ": a row does not fit its header; the file is kept as " << kept.string()
              << " and a fresh one begins\n";
    return true;
  }
  if (dropped) {
    fs::path kept = learn::keep_aside_before_resume(file);
    std::cerr << name << ": written with other columns, kept whole as " << kept.string()
              << "; its rows go on under the current header (unknown columns left out)\n";
  } else {
    std::cerr << name << ": rows of an older header rewritten under the current one (new columns "
              << "empty)\n";
  }
  write_atomically(file, text.str());
  return false;
}

// The teacher's build: the registry's setup from the run's options and the env's facts.
std::unique_ptr<teach::Teacher> make_run_teacher(const StudentEnv& env, const StudentRunOptions& o,
                                                 const teach::DimensionShuffle* shuffle) {
  teach::TeacherSetup setup{.name = o.teacher,
                            .mins = env.space.mins(),
                            .maxs = env.space.maxs(),
                            .seed = o.seed,
                            .expert_knowledge = teach::parse_expert_knowledge(o.expert_knowledge),
                            .initial_dist = env.initial_dist,
                            .reward_lb = env.reward_lb,
                            .reward_ub = env.reward_ub,
                            .scale_reward = o.scale_reward,
                            .params = o.teacher_params};
  // The teacher works in the shuffled space: the easy region's mean maps there.
  if (shuffle && setup.initial_dist) {
    setup.initial_dist->mean = shuffle->to_shuffled(setup.initial_dist->mean);
  }
  return teach::make_teacher(setup);
}

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
  StudentEnv env{.make = [options] { return std::make_unique<envs::TmaEnvAdapter>(options); },
                 .space = teach::TaskSpace::from_json(bounds),
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

namespace {

// The resume point of a run: checkpoints/latest.json, every key checked.
struct ResumePoint {
  long env_steps = 0, learner_steps = 0, step_offset = 0, episodes = 0;
  int student_resets = 0, evaluation = 0;
  double wall_s = 0;
  std::map<std::string, std::uintmax_t> sizes;  // of kLogs
};

ResumePoint read_resume_point(const fs::path& file) {
  const RunJson j(file, "the resume point of a `cradle tma run` run (checkpoints/latest.json)");
  ResumePoint p{.env_steps = j.count("env_steps"),
                .learner_steps = j.count("learner_steps"),
                .step_offset = j.count("step_offset"),
                .episodes = j.count("episodes"),
                .student_resets = static_cast<int>(std::min(j.count("student_resets"), 1L << 30)),
                .evaluation = static_cast<int>(std::min(j.count("evaluation"), 1L << 30)),
                .wall_s = j.number("wall_s")};
  if (p.wall_s < 0) {
    throw UserError(j.where() + ": \"wall_s\" is " + std::to_string(p.wall_s) +
                    "; expected seconds >= 0");
  }
  const RunJson sizes = j.object("sizes");
  for (const char* name : kLogs) p.sizes[name] = sizes.unsigned_integer(name);
  return p;
}

// The checkpoint a resume point names: checkpoints/step_<env_steps>.ckpt (latest.ckpt in folders
// of builds that wrote no step file).
fs::path resume_checkpoint(const fs::path& checkpoints, long env_steps) {
  const fs::path step = checkpoints / ("step_" + std::to_string(env_steps) + ".ckpt");
  return fs::exists(step) ? step : checkpoints / "latest.ckpt";
}

// The files a run writes in its folder (removed by --overwrite).
const char* const kRunFiles[] = {"run.json",     "progress.csv",  "test_returns.csv",
                                 "test_set.csv", "teacher.jsonl", "summary.json",
                                 "checkpoints"};

}  // namespace

StudentRunResult run_student(const StudentEnv& env, const StudentRunOptions& o) {
  // Options first: nothing is written for a bad one.
  if (o.total_steps < 1) throw UserError("--nb_env_steps must give at least 1 env step");
  if (o.test_every < 1) throw UserError("--test_every must be at least 1");
  if (o.nb_test_episodes < 1) throw UserError("--nb_test_episodes must be at least 1");
  if (o.reset_frequency < 0) throw UserError("--reset_frequency must be >= 0 (0: never)");
  if (o.out.empty()) throw UserError("--out: no run folder given");
  if (o.resume && o.overwrite) throw UserError("--resume and --overwrite: give one of them");
  std::map<std::string, std::string> hyperparameters = student_preset(o.student, o.total_steps);
  for (const auto& [k, v] : o.hyperparameters) hyperparameters[k] = v;

  const fs::path dir = o.out;
  const fs::path checkpoints = dir / "checkpoints";
  const fs::path latest = checkpoints / "latest.ckpt";
  const fs::path state_file = checkpoints / "latest.json";
  // A folder that holds a run is continued (--resume) or replaced (--overwrite), never silently.
  {
    std::error_code ec;
    if (fs::exists(dir, ec) && !fs::is_directory(dir, ec)) {
      throw UserError("--out '" + dir.string() + "' is a file; expected a run folder");
    }
    const bool holds_run = fs::exists(dir / "run.json", ec) ||
                           fs::exists(dir / "progress.csv", ec) || fs::exists(state_file, ec);
    if (holds_run && !o.resume && !o.overwrite) {
      throw UserError("--out '" + dir.string() +
                      "' holds a run; give --resume to continue it, --overwrite to replace it, or "
                      "another folder");
    }
    if (o.overwrite) {
      for (const char* name : kRunFiles) fs::remove_all(dir / name, ec);
    }
  }
  nlohmann::ordered_json run_json;
  run_json["arguments"] = o.arguments;
  run_json["student"] = o.student;
  run_json["teacher"] = o.teacher;
  run_json["teacher_params"] = o.teacher_params;
  run_json["expert_knowledge"] = o.expert_knowledge;
  run_json["env_steps"] = o.total_steps;
  run_json["test_every"] = o.test_every;
  run_json["seed"] = o.seed;
  run_json["shuffle_dimensions"] = o.shuffle_dimensions;
  run_json["scale_reward"] = o.scale_reward;
  run_json["reset_frequency"] = o.reset_frequency;
  run_json["keep_periodical_task_samples"] = o.keep_periodical_task_samples;
  run_json["reward_bounds"] = {env.reward_lb, env.reward_ub};
  run_json["success_threshold"] = env.success_threshold;
  run_json["hyperparameters"] = hyperparameters;
  run_json["bounds"] = env.space.bounds_json();
  run_json["commit"] = o.commit;
  run_json["cradle_version"] = CRADLE_VERSION;

  // The controller: the teacher in the (maybe shuffled) space, the test set, the books.
  std::unique_ptr<teach::DimensionShuffle> shuffle;
  if (o.shuffle_dimensions) {
    shuffle = std::make_unique<teach::DimensionShuffle>(env.space.mins(), env.space.maxs(), o.seed);
  }
  std::vector<teach::Task> test_set =
      env.test_set.empty() ? teach::default_test_set(env.space, o.nb_test_episodes) : env.test_set;
  auto controller = std::make_shared<teach::TeacherController>(
      make_run_teacher(env, o, shuffle.get()), env.space,
      teach::ControllerOptions{.seed = o.seed,
                               .shuffle_dimensions = o.shuffle_dimensions,
                               .scale_reward = o.scale_reward,
                               .reward_lb = env.reward_lb,
                               .reward_ub = env.reward_ub,
                               .test_set = test_set,
                               .keep_periodical_task_samples = o.keep_periodical_task_samples});
  // The training env (one, as the reference) and a separate test env.
  std::vector<std::unique_ptr<envs::Env>> list;
  auto curriculum = std::make_unique<CurriculumEnv>(
      env.make(), controller, CurriculumOptions{.success_threshold = env.success_threshold});
  CurriculumEnv* train_env = curriculum.get();
  list.push_back(std::move(curriculum));
  learn::ThreadedVecEnv vec(std::move(list), 1);
  std::unique_ptr<envs::Env> test_env = env.make();

  // The student; a reset gives a fresh one (criterion 3) with its own seed.
  long offset = 0;
  int student_resets = 0;
  auto make_student = [&] {
    learn::LearnerOptions lo{.seed = o.seed + 7919 * static_cast<std::uint64_t>(student_resets),
                             .hyperparameters = hyperparameters};
    return learn::make_learner(o.student, vec, lo);
  };
  std::unique_ptr<learn::Learner> learner = make_student();
  // SPDL values its tasks with the student's value function (the current student after a reset).
  controller->teacher().set_value_estimator(learner_value_estimator(
      [&learner]() -> learn::Learner& { return *learner; }, vec.observation_space()));

  // Resume: the same arguments (but the resumable ones), the resume point's checkpoint, every
  // file checked before anything is cut or changed.
  ResumePoint state;
  fs::path resume_from;
  if (o.resume) {
    if (!fs::exists(state_file)) {
      throw UserError("--resume: no checkpoint in '" + checkpoints.string() + "'");
    }
    const RunJson saved(dir / "run.json", "the run.json of a `cradle tma run` run");
    const RunJson saved_arguments = saved.object("arguments");
    for (const auto& [key, value] : o.arguments.items()) {
      if (std::find(std::begin(kResumable), std::end(kResumable), key) != std::end(kResumable))
        continue;
      const nlohmann::json before = saved_arguments.json().value(key, nlohmann::json());
      if (before != nlohmann::json::parse(value.dump())) {
        throw UserError("--resume: --" + key + " is " + value.dump() + " but the run had " +
                        before.dump() + " (give the run's arguments again)");
      }
    }
    state = read_resume_point(state_file);
    resume_from = resume_checkpoint(checkpoints, state.env_steps);
    if (learn::load_run_state(resume_from, nullptr).steps != state.learner_steps) {
      throw UserError("--resume: '" + resume_from.string() + "' and '" + state_file.string() +
                      "' are of different steps");
    }
    // The teacher's book is checked whole before the logs are cut back to the checkpoint.
    check_teacher_book(dir / "teacher.jsonl", env.space.dims());
    for (const char* name : kLogs) learn::cut_to_checkpoint(dir / name, state.sizes[name]);
  } else {
    make_folder(dir, "cannot create the run folder");
    make_folder(checkpoints, "cannot create the run folder");
  }
  write_atomically(dir / "run.json", run_json.dump(2) + "\n");

  // test_set.csv: the tasks in evaluation order.
  {
    std::ostringstream csv;
    csv << "task_index";
    for (const std::string& n : env.space.dim_names()) csv << "," << n;
    csv << "\n";
    for (std::size_t i = 0; i < test_set.size(); ++i) {
      csv << i;
      for (float v : test_set[i]) csv << "," << csv_cell(v);
      csv << "\n";
    }
    write_atomically(dir / "test_set.csv", csv.str());
  }
  // A resumed teacher hears the booked episodes again, in order.
  if (o.resume) replay_teacher_book(*controller, dir / "teacher.jsonl", /*periodical=*/true);

  if (o.resume) {
    offset = state.step_offset;
    student_resets = state.student_resets;
    if (student_resets > 0) learner = make_student();
    learner->load(resume_from);
  }
  auto run_steps = [&] { return offset + learner->steps(); };

  // The logs: appended to on resume (already cut back; an older binary's columns adopted, and
  // the resume point's sizes then follow the rewritten files), fresh otherwise.
  bool progress_header = true, test_header = true;
  if (o.resume) {
    progress_header = adopt_header(dir / "progress.csv", kProgressHeader);
    test_header = adopt_header(dir / "test_returns.csv", kTestHeader);
    bool changed = false;
    for (const char* name : {"progress.csv", "test_returns.csv"}) {
      std::error_code ec;
      const std::uintmax_t size = fs::exists(dir / name, ec) ? fs::file_size(dir / name, ec) : 0;
      changed = changed || size != state.sizes[name];
      state.sizes[name] = size;
    }
    if (changed) {
      nlohmann::json saved = nlohmann::json::parse(std::ifstream(state_file));
      for (const char* name : {"progress.csv", "test_returns.csv"})
        saved["sizes"][name] = state.sizes[name];
      write_atomically(state_file, saved.dump(2) + "\n");
    }
  }
  std::ofstream progress(dir / "progress.csv", progress_header ? std::ios::trunc : std::ios::app);
  std::ofstream test_csv(dir / "test_returns.csv", test_header ? std::ios::trunc : std::ios::app);
  if (!progress || !test_csv)
    throw UserError("cannot write the run's logs in '" + dir.string() + "'");
  if (progress_header) progress << kProgressHeader << "\n";
  if (test_header) test_csv << kTestHeader << "\n";
  JsonlWriter teacher_log(dir / "teacher.jsonl", o.resume);

  int evaluation = o.resume ? state.evaluation + 1 : 0;
  const double wall_before = o.resume ? state.wall_s : 0.0;
  const auto start = Clock::now();
  const long first_steps = run_steps();
  auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  StudentRunResult result;
  result.checkpoint_steps = first_steps;
  double train_return_sum = 0;
  long train_returns = 0;
  // SAC's update counter (per learner; a resumed one counts from its first report).
  double updates_done = std::nan(""), updates_seen = std::nan("");

  // Booked episodes and snapshots to teacher.jsonl as they come.
  auto drain_teacher = [&] {
    for (const teach::EpisodeRecord& e : controller->take_episodes()) {
      teacher_log.write(teach::train_line(e));
      train_return_sum += e.ret;
      ++train_returns;
    }
    for (const teach::PeriodicalRecord& p : controller->take_periodical())
      teacher_log.write({{"kind", "periodical"}, {"env_steps", p.env_steps}, {"tasks", p.tasks}});
  };

  // The resume point, one atomic step: the checkpoint goes to step_<N>.ckpt (a new file), then
  // latest.json names N (a rename), then latest.ckpt becomes the same file and the previous step
  // file goes. A kill at any point leaves a latest.json whose checkpoint exists.
  long last_step_file = o.resume ? state.env_steps : -1;
  auto save_resume_point = [&](long steps, double wall) {
    const fs::path step_file = checkpoints / ("step_" + std::to_string(steps) + ".ckpt");
    learn::save_run_checkpoint(step_file, *learner, nullptr,
                               {.steps = learner->steps(), .episodes = controller->episodes()});
    nlohmann::json saved{{"env_steps", steps},
                         {"learner_steps", learner->steps()},
                         {"step_offset", offset},
                         {"student_resets", student_resets},
                         {"evaluation", evaluation},
                         {"episodes", controller->episodes()},
                         {"wall_s", wall}};
    for (const char* name : kLogs) saved["sizes"][name] = fs::file_size(dir / name);
    write_atomically(state_file, saved.dump(2) + "\n");
    const fs::path tmp = latest.string() + ".tmp";
    std::error_code ec;
    fs::remove(tmp, ec);
    fs::create_hard_link(step_file, tmp, ec);
    if (ec) fs::copy_file(step_file, tmp, fs::copy_options::overwrite_existing, ec);
    if (!ec) fs::rename(tmp, latest, ec);
    if (ec) throw UserError("cannot write '" + latest.string() + "': " + ec.message());
    if (last_step_file >= 0 && last_step_file != steps) {
      fs::remove(checkpoints / ("step_" + std::to_string(last_step_file) + ".ckpt"), ec);
    }
    last_step_file = steps;
  };

  // One evaluation: every test task once, deterministic policy (the one evaluation rollout),
  // then the files and the resume point.
  auto evaluate = [&] {
    const auto eval_start = Clock::now();
    const long steps = run_steps();
    drain_teacher();
    const std::vector<std::string>& names = env.space.dim_names();
    std::vector<teach::Task> tasks;
    std::vector<std::uint64_t> seeds;
    for (int i = 0; i < controller->test_set_size(); ++i) {
      tasks.push_back(controller->next_test_task());
      seeds.push_back(o.seed * 1000003 + 100000 + static_cast<std::uint64_t>(i));
    }
    learn::Learner* student = learner.get();
    const std::vector<EpisodeOutcome> episodes = run_episodes(
        *test_env,
        {.act = [student](const envs::ObservationBuffers& obs,
                          std::span<double> action) { student->act(obs, action, true); }},
        seeds, 0, nullptr, [&](int i, envs::Env& e) {
          envs::ResetOptions task_options;
          for (std::size_t d = 0; d < names.size(); ++d) task_options[names[d]] = tasks[i][d];
          e.set_reset_options(task_options);
        });
    double mean = 0, var = 0;
    int mastered = 0;
    for (std::size_t i = 0; i < episodes.size(); ++i) {
      const double ret = episodes[i].episode_return;
      controller->record_test_episode(ret, episodes[i].length);
      test_csv << evaluation << "," << steps << "," << i << "," << csv_cell(ret) << ","
               << (ret > env.success_threshold ? 1 : 0) << "\n";
      mean += ret / episodes.size();
      mastered += ret > env.success_threshold;
    }
    for (const EpisodeOutcome& e : episodes)
      var += (e.episode_return - mean) * (e.episode_return - mean) / episodes.size();
    const double pct = 100.0 * mastered / episodes.size();
    result.eval_s += std::chrono::duration<double>(Clock::now() - eval_start).count();
    const double wall = wall_before + elapsed();
    progress << evaluation << "," << steps << "," << controller->episodes() << "," << csv_cell(wall)
             << "," << csv_cell((steps - first_steps) / std::max(elapsed(), 1e-9)) << ","
             << csv_cell(mean) << "," << csv_cell(std::sqrt(var)) << "," << csv_cell(pct) << ","
             << csv_cell(train_returns ? train_return_sum / train_returns : std::nan("")) << ","
             << csv_cell(updates_done) << "," << csv_cell(train_env->teacher_seconds()) << "\n";
    train_return_sum = 0;
    train_returns = 0;
    teacher_log.write(teach::dump_line(steps, controller->teacher_dump()));
    progress.flush();
    test_csv.flush();
    teacher_log.flush();
    if (!progress || !test_csv)
      throw UserError("cannot write the run's logs in '" + dir.string() + "'");
    save_resume_point(steps, wall);
    result.last_pct_mastered = pct;
    result.checkpoint_steps = steps;
    ++result.evaluations;
    ++evaluation;
  };

  // Evaluation 0 before training; then the shared loop trains exactly to each evaluation and
  // student reset in turn, and the run evaluates once more at its end.
  long last_evaluated = o.resume ? state.env_steps : -1;
  auto evaluate_now = [&] {
    evaluate();
    last_evaluated = run_steps();
  };
  if (!o.resume) evaluate_now();
  auto next_multiple = [&](long every) { return (run_steps() / every + 1) * every; };
  long next_eval = next_multiple(o.test_every);
  long next_reset = o.reset_frequency > 0 ? next_multiple(o.reset_frequency) : o.total_steps;
  auto stopped = [&] { return o.stop && o.stop->load(); };
  const ProgressBar bar(o.total_steps, first_steps, o.progress_bar);
  run_loop([&]() -> learn::Learner& { return *learner; },
           {.total_steps = o.total_steps,
            .next_boundary = [&](long) { return std::min(next_eval, next_reset); },
            .offset = [&] { return offset; },
            .report =
                [&](const learn::TrainStats& s) {
                  const auto it = s.losses.find("updates");
                  if (it != s.losses.end()) {
                    if (std::isnan(updates_done)) updates_done = 0;
                    if (std::isnan(updates_seen)) updates_seen = o.resume ? it->second : 0;
                    updates_done += it->second - updates_seen;
                    updates_seen = it->second;
                  }
                  drain_teacher();
                  bar.show(offset + s.steps, elapsed(),
                           "mastered " + csv_cell(result.last_pct_mastered) + "%");
                  return true;
                },
            // A fresh student (networks, optimiser, buffer) every reset_frequency steps, then the
            // evaluation when one is due.
            .at_boundary =
                [&] {
                  if (o.reset_frequency > 0 && run_steps() >= next_reset) {
                    offset = run_steps();
                    ++student_resets;
                    learner = make_student();
                    updates_seen = 0;
                    next_reset = next_multiple(o.reset_frequency);
                  }
                  if (run_steps() >= next_eval) {
                    evaluate_now();
                    next_eval = next_multiple(o.test_every);
                  }
                },
            .stopping = stopped});
  if (run_steps() >= o.total_steps && run_steps() != last_evaluated) evaluate_now();
  bar.finish();
  drain_teacher();
  teacher_log.flush();

  result.env_steps = run_steps();
  result.stopped = stopped() && result.env_steps < o.total_steps;
  result.episodes = controller->episodes();
  result.wall_s = elapsed();
  result.env_steps_per_s = (result.env_steps - first_steps) / std::max(result.wall_s, 1e-9);
  result.gradient_steps = updates_done;
  result.gradient_steps_per_s = result.gradient_steps / std::max(result.wall_s, 1e-9);
  result.teacher_s = train_env->teacher_seconds();
  nlohmann::ordered_json summary{
      {"env_steps", result.env_steps},
      {"episodes", result.episodes},
      {"evaluations", result.evaluations},
      {"wall_s", result.wall_s},
      {"env_steps_per_s", result.env_steps_per_s},
      {"gradient_steps", result.gradient_steps},
      {"gradient_steps_per_s", result.gradient_steps_per_s},
      {"teacher_s", result.teacher_s},
      {"teacher_share", result.teacher_s / std::max(result.wall_s, 1e-9)},
      {"eval_s", result.eval_s},
      {"pct_mastered", result.last_pct_mastered},
      {"stopped", result.stopped},
      {"checkpoint_env_steps", result.checkpoint_steps}};
  if (std::isnan(result.gradient_steps)) {
    summary["gradient_steps"] = nullptr;
    summary["gradient_steps_per_s"] = nullptr;
  }
  write_atomically(dir / "summary.json", summary.dump(2) + "\n");
  return result;
}

namespace {

// Whether the run folder's run.json records body or Parkour options.
bool run_has_env_options(const fs::path& dir) {
  // Only a readable file counts; the resume itself names a damaged one.
  std::error_code ec;
  if (!fs::is_regular_file(dir / "run.json", ec)) return false;
  std::ifstream in(dir / "run.json");
  if (!in) return false;
  const nlohmann::json run = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  return run.is_object() && run.contains("arguments") && run["arguments"].is_object() &&
         run["arguments"].contains("env_options");
}

}  // namespace

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
  StudentRunOptions o{.student = a.student,
                      .teacher = a.teacher,
                      .expert_knowledge = a.expert_knowledge,
                      .total_steps = a.steps > 0 ? a.steps : std::lround(millions * 1e6),
                      .test_every = a.test_every,
                      .nb_test_episodes = a.nb_test_episodes,
                      .seed = a.seed,
                      .keep_periodical_task_samples = a.keep_periodical_task_samples,
                      .shuffle_dimensions = a.shuffle_dimensions,
                      .scale_reward = a.scale_reward,
                      .reset_frequency = a.reset_frequency,
                      .resume = a.resume,
                      .overwrite = a.overwrite,
                      .progress_bar = a.progress_bar};
  o.teacher_params = teach::parse_teacher_params(a.teacher_params);
  o.hyperparameters = learn::parse_hyperparameter_flags(a.hp);
  // learning_rate with --lr would keep only one value, silently.
  if (a.lr != 0 && !o.hyperparameters.emplace("learning_rate", std::to_string(a.lr)).second)
    throw UserError("--hp learning_rate is given twice (also by --lr); expected each name once");
  o.out = a.out.empty()
              ? fs::path("tma_runs") / a.exp_name / (a.exp_name + "_s" + std::to_string(a.seed))
              : fs::path(a.out);
  o.arguments = {{"exp_name", a.exp_name},
                 {"env", a.env},
                 {"embodiment", a.body},
                 {"student", a.student},
                 {"teacher", a.teacher},
                 {"teacher_params", o.teacher_params},
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
                 {"out", o.out.string()},
                 {"resume", a.resume}};
  // Recorded when given, or when resuming a run that has them (so that leaving them out is
  // refused by name); runs without them resume as before.
  nlohmann::json env_options = nlohmann::json::object();
  for (const auto& [name, value] : a.env_options) env_options[name] = value;
  if (!env_options.empty() || (a.resume && run_has_env_options(o.out))) {
    o.arguments["env_options"] = env_options;
  }
  o.commit = a.commit;
  o.stop = a.stop;
  // The env family's half of the run: the env with its options and the benchmark's facts.
  tma::TmaOptions options{.env = tma::parse_env_id(a.env), .body = a.body};
  for (const auto& [name, value] : a.env_options) tma::set_option(options, name, value);
  const StudentEnv env = tma_student_env(options, {.min_stump_h = a.min_stump_h,
                                                   .max_stump_h = a.max_stump_h,
                                                   .max_obstacle_spacing = a.max_obstacle_spacing,
                                                   .test_set = a.test_set});
  return {.out = o.out, .result = run_student(env, o)};
}

}  // namespace cradle::train

// `cradle illustrate --env reach|standup|selfbody|catch [--train_for N] [--test_for M]
// [--algorithm PPO|SAC|TD3|DDPG|A2C] [--save_every K] [--save_model NAME] [--load_model PATH]
// [--use_muscles] [--render_video] [--stochastic] [--envs K] [--seed S] [--hp name=value]
// [--task-space FILE.yml [--teacher T]]`: the
// reference's illustrations.py. Trains a policy on a MIMo sample env (checkpoints
// models/<env>/<name>/model_<k>.ckpt every save_every steps, progress.csv, learning-curve PNGs),
// then runs test_for steps with it (or with random actions when there is no model), optionally
// filming each episode, and prints the success rate and the mean return per episode. Without
// --algorithm the algorithm is the --load_model checkpoint's; without either, testing takes
// random actions (training then needs --algorithm).
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "apps/cli_checks.h"
#include "apps/commands.h"
#include "core/error.h"
#include "core/folders.h"
#include "core/jsonl.h"
#include "core/rng.h"
#include "envs/mimo/sample_env.h"
#include "eval/figures.h"
#include "eval/video.h"
#include "learn/hyperparams.h"
#include "learn/registry.h"
#include "learn/vector_env.h"
#include "train/loop.h"
#include "train/task_space.h"

namespace cradle::apps {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using train::csv_cell;

struct IllustrateOptions {
  std::string env;
  long train_for = 0;
  long test_for = 1000;
  long save_every = 100000;
  std::string algorithm;
  std::string load_model;
  std::string save_model = "model";
  bool render_video = false;
  bool use_muscles = false;
  bool stochastic = false;
  bool jitter = false, position_inaccurate = false, palm_up = false;  // catch only
  bool overwrite = false;  // replace the models already saved under --save_model
  int envs = 1;
  std::uint64_t seed = 0;
  std::vector<std::string> hp;
  std::string task_space, teacher;  // a curriculum (docs/curricula.md)
};

// The learner's name for a reference algorithm name; HER is refused.
std::string learner_name(const std::string& algorithm) {
  std::string upper = algorithm;
  std::ranges::transform(upper, upper.begin(), [](unsigned char c) { return std::toupper(c); });
  if (upper == "HER") {
    throw UserError(
        "--algorithm HER is not supported (the reference accepts it but never uses it); use PPO, "
        "SAC, TD3, DDPG or A2C");
  }
  for (const char* known : {"PPO", "SAC", "TD3", "DDPG", "A2C"}) {
    if (upper == known) {
      std::string lower = upper;
      std::ranges::transform(lower, lower.begin(), [](unsigned char c) { return std::tolower(c); });
      return lower;
    }
  }
  throw UserError("--algorithm '" + algorithm + "': expected one of PPO, SAC, TD3, DDPG, A2C");
}

// Learning curves of a training run, one point per update (NaN where no episode ended).
struct Curves {
  std::vector<double> steps, returns, success_rates;
};

// learning_curve_return.png and learning_curve_success.png in `dir` (matplotlib); true when drawn.
bool plot_curves(const Curves& c, const std::string& title, const fs::path& dir) {
  auto series = [&](const std::vector<double>& y, const char* label) {
    return eval::Series{.label = label, .x = c.steps, .y = y};
  };
  eval::Figures figures;
  figures.add(eval::LinePlot{.title = title + ": training return",
                             .x_label = "env steps",
                             .y_label = "return",
                             .series = {series(c.returns, "episodic return")}},
              dir / "learning_curve_return.png");
  figures.add(eval::LinePlot{.title = title + ": training success rate",
                             .x_label = "env steps",
                             .y_label = "success rate",
                             .series = {series(c.success_rates, "success rate")},
                             .y_range = std::pair{0.0, 1.0}},
              dir / "learning_curve_success.png");
  return figures.draw(dir / "figures.json");
}

void run(const IllustrateOptions& o) {
  // Flags first, before anything is built.
  const std::string id = envs::sample_env_id(o.env);
  // No --algorithm: the checkpoint's (--load_model), else none (testing with random actions).
  std::string algorithm = o.algorithm.empty() ? "" : learner_name(o.algorithm);
  if (algorithm.empty() && o.load_model.empty() && o.train_for > 0) {
    throw UserError("--train_for needs --algorithm (PPO, SAC, TD3, DDPG or A2C) or --load_model");
  }
  if (o.train_for < 0 || o.test_for < 0) throw UserError("--train_for and --test_for must be >= 0");
  if (o.save_every < 1) throw UserError("--save_every must be at least 1");
  if (o.envs < 1) throw UserError("--envs must be at least 1");
  if (o.save_model.empty() || o.save_model.find('/') != std::string::npos) {
    throw UserError("--save_model '" + o.save_model + "': expected a plain name");
  }
  if (!o.load_model.empty() && !fs::is_regular_file(o.load_model)) {
    throw UserError("--load_model '" + o.load_model + "' does not exist");
  }
  std::map<std::string, std::string> hyperparameters = learn::parse_hyperparameter_flags(o.hp);
  // Models trained before under this name are never replaced silently.
  const fs::path saved = fs::path("models") / o.env / o.save_model;
  if (o.train_for > 0 && !o.overwrite && fs::exists(saved / "progress.csv")) {
    throw UserError("'" + saved.string() +
                    "' holds models trained before; give --overwrite to replace them or another "
                    "--save_model");
  }
  if (!o.load_model.empty()) {
    const learn::CheckpointInfo info = learn::read_checkpoint_info(o.load_model);
    if (algorithm.empty()) algorithm = info.algorithm;
    if (info.algorithm != algorithm) {
      throw UserError("--load_model '" + o.load_model + "' holds a " + info.algorithm +
                      " model, not " + algorithm);
    }
    // The saved hyperparameters, then the user's overrides.
    auto saved = learn::parse_hyperparameter_text(info.config);
    for (auto& [k, v] : hyperparameters) saved[k] = v;
    hyperparameters = std::move(saved);
  }
  const fs::path dir = fs::path("models") / o.env / o.save_model;

  // The reference passes the actuation model explicitly: muscles only with --use_muscles.
  envs::SampleOptions env_options;
  env_options.actuation = o.use_muscles ? ActuationModel::kMuscle : ActuationModel::kSpringDamper;
  env_options.jitter = o.jitter;
  env_options.position_inaccurate = o.position_inaccurate;
  env_options.palm_up = o.palm_up;
  const auto assets = envs::make_sample_assets(id, env_options);

  // A curriculum: one teacher sets every training env's task options before its resets.
  if (!o.teacher.empty() && o.task_space.empty())
    throw UserError("--teacher needs --task-space FILE.yml (the parameters it sets)");
  std::optional<train::CurriculumSpec> spec;
  std::shared_ptr<teach::TeacherController> curriculum;
  if (!o.task_space.empty()) {
    spec = train::load_task_space(o.task_space);
    if (!o.teacher.empty()) spec->teacher = o.teacher;
    curriculum = train::make_controller(*spec, o.seed);
  }

  // The learner trains on a vector of envs sharing the compiled scene.
  std::unique_ptr<learn::ThreadedVecEnv> vec = std::make_unique<learn::ThreadedVecEnv>(
      o.envs,
      [&](int i) -> std::unique_ptr<envs::Env> {
        auto env = envs::make_sample_env(assets, learn::ThreadedVecEnv::env_seed(o.seed, i));
        if (!curriculum) return env;
        return std::make_unique<train::CurriculumEnv>(std::move(env), curriculum,
                                                      spec->env_options);
      },
      o.envs);
  std::unique_ptr<learn::Learner> learner;
  long successes = 0, ended = 0;  // training episodes, counted by the reward hook
  if (o.train_for > 0 || !o.load_model.empty()) {
    learn::LearnerOptions lo{.seed = o.seed, .hyperparameters = hyperparameters};
    const int success = vec->info(0).find("is_success");
    lo.reward_hook = [&, success](const learn::VecEnv& env, std::span<const double>,
                                  std::span<double>) {
      for (int i = 0; i < env.num_envs(); ++i) {
        if (env.terminated()[i] || env.truncated()[i]) {
          ++ended;
          successes += env.info(i).flag(success);
        }
      }
    };
    learner = learn::make_learner(algorithm, *vec, lo);
    if (!o.load_model.empty()) learner->load(o.load_model);
    if (curriculum)  // SPDL values its tasks with the student's value function
      curriculum->teacher().set_value_estimator(train::learner_value_estimator(
          [&learner]() -> learn::Learner& { return *learner; }, vec->observation_space()));
  }

  // Training: checkpoints model_<k>.ckpt after every save_every steps, progress.csv per update.
  if (o.train_for > 0) {
    std::error_code ec;
    // --overwrite: the earlier run's models and curves go (after --load_model was read).
    if (o.overwrite) {
      for (const auto& entry : fs::directory_iterator(dir, ec)) {
        const std::string name = entry.path().filename().string();
        if (name.starts_with("model_") || name == "progress.csv" || name.ends_with(".png") ||
            name == "figures.json")
          fs::remove(entry.path(), ec);
      }
    }
    make_folder(dir, "cannot create");
    std::ofstream csv(dir / "progress.csv");
    if (!csv) throw UserError("cannot write '" + (dir / "progress.csv").string() + "'");
    csv << "global_step,time,charts/SPS,charts/episodic_return,charts/episodic_length,"
           "charts/success_rate,episodes\n";
    const long first = learner->steps();
    const long total = first + o.train_for;
    long next_save = first + o.save_every;
    int saved = 0;
    long saved_at = first;
    long last_report = first;
    const auto start = Clock::now();
    std::printf("training %s on %s for %ld steps (%d envs) -> %s\n", algorithm.c_str(), id.c_str(),
                o.train_for, o.envs, dir.c_str());
    // Success rate of the episodes that ended since the last update.
    long successes_seen = 0, ended_seen = 0;
    Curves curves;
    // The shared training loop; models are saved as the run goes (no boundaries, so one learn()
    // call and the reference's episodes).
    const auto report = [&](const learn::TrainStats& s) {
      const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
      const double rate = ended > ended_seen ? static_cast<double>(successes - successes_seen) /
                                                   static_cast<double>(ended - ended_seen)
                                             : std::nan("");
      successes_seen = successes;
      ended_seen = ended;
      csv << s.steps << "," << csv_cell(elapsed) << "," << csv_cell(s.sps) << ","
          << csv_cell(s.episodic_return) << "," << csv_cell(s.episodic_length) << ","
          << csv_cell(rate) << "," << s.episodes << "\n";
      csv.flush();
      curves.steps.push_back(static_cast<double>(s.steps));
      curves.returns.push_back(s.episodic_return);
      curves.success_rates.push_back(rate);
      if (s.steps >= next_save) {
        learner->save(dir / ("model_" + std::to_string(++saved) + ".ckpt"));
        saved_at = s.steps;
        next_save += o.save_every;
      }
      if (s.steps - last_report >= std::max<long>(o.train_for / 20, 1) || s.steps >= total) {
        last_report = s.steps;
        std::printf("  %9ld steps  %6.0f s  %6.0f steps/s  return %s  length %s  success %s\n",
                    s.steps, elapsed, s.sps, csv_cell(s.episodic_return).c_str(),
                    csv_cell(s.episodic_length).c_str(), csv_cell(rate).c_str());
        std::fflush(stdout);
      }
      return true;
    };
    train::run_loop(*learner, {.total_steps = total, .report = report});
    if (learner->steps() > saved_at) {
      learner->save(dir / ("model_" + std::to_string(++saved) + ".ckpt"));
    }
    // The curriculum's book: every training episode's task and outcome, then the teacher's dump.
    if (curriculum) {
      JsonlWriter book(dir / "teacher.jsonl", /*append=*/false);
      for (const teach::EpisodeRecord& e : curriculum->take_episodes())
        book.write(teach::train_line(e));
      book.write(teach::dump_line(curriculum->env_steps(), curriculum->teacher_dump()));
      book.flush();
      std::printf("curriculum: %ld episodes booked in %s\n", curriculum->episodes(),
                  (dir / "teacher.jsonl").c_str());
    }
    const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
    std::printf("trained %ld steps in %.0f s; last model: %s\n", learner->steps() - first, seconds,
                (dir / ("model_" + std::to_string(saved) + ".ckpt")).c_str());
    if (!curves.steps.empty() &&
        plot_curves(curves, id + " " + (o.algorithm.empty() ? algorithm : o.algorithm), dir)) {
      std::printf("learning curves: %s/learning_curve_{return,success}.png\n", dir.c_str());
    }
  }
  // The vector stays alive: the learner keeps a reference to it.

  // Testing: one env, the policy's deterministic action (random actions without a model).
  if (o.test_for == 0) return;
  auto env = envs::make_sample_env(assets, o.seed + 1000);
  const Box& space = env->action_space();
  std::vector<double> action(space.size());
  Rng rng(o.seed + 2000);
  std::vector<std::uint8_t> frame(static_cast<size_t>(env->render_size()) * env->render_size() * 3);
  const double fps = 1.0 / (env->definition().frame_skip * env->model()->opt.timestep);
  std::optional<eval::VideoWriter> video;
  auto start_video = [&](int episode) {
    if (!o.render_video) return;
    std::error_code ec;
    fs::create_directories(dir, ec);
    video.emplace(dir / ("episode_" + std::to_string(episode) + ".mp4"), env->render_size(),
                  env->render_size(), fps);
    env->render(frame);
    video->write(frame);
  };
  struct Episode {
    double ret = 0;
    int length = 0;
    bool success = false;
  };
  std::vector<Episode> episodes;  // the ones that ended
  Episode current;
  start_video(0);
  std::printf("testing %s for %ld steps with %s\n", id.c_str(), o.test_for,
              !learner       ? "random actions"
              : o.stochastic ? "the trained policy (sampled actions)"
                             : "the trained policy");
  for (long t = 0; t < o.test_for; ++t) {
    if (learner) {
      learner->act(env->observation(), action, /*deterministic=*/!o.stochastic);
    } else {
      space.sample(rng, action);
    }
    const envs::StepResult r = env->step(action);
    current.ret += r.reward;
    ++current.length;
    current.success = env->success();
    if (video) {
      env->render(frame);
      video->write(frame);
    }
    if (r.terminated || r.truncated) {
      std::printf("  episode %zu: %d steps, return %.2f, %s\n", episodes.size(), current.length,
                  current.ret, current.success ? "success" : "no success");
      episodes.push_back(current);
      current = {};
      if (video) video->close();
      if (t + 1 < o.test_for) {
        env->reset();
        start_video(static_cast<int>(episodes.size()));
      }
    }
  }
  if (video) video->close();
  // An episode cut short by the end of testing counts only when none ended.
  if (episodes.empty()) episodes.push_back(current);
  double returns = 0;
  int successes_test = 0;
  for (const Episode& e : episodes) {
    returns += e.ret;
    successes_test += e.success;
  }
  const double n = static_cast<double>(episodes.size());
  std::printf("%zu test episodes: success rate %.1f %% (%d/%zu), mean return %.3f\n",
              episodes.size(), 100.0 * successes_test / n, successes_test, episodes.size(),
              returns / n);
  if (o.render_video) std::printf("videos: %s/episode_<i>.mp4\n", dir.c_str());
}

}  // namespace

void register_illustrate(CLI::App& app) {
  auto o = std::make_shared<IllustrateOptions>();
  CLI::App* cmd = app.add_subcommand(
      "illustrate", "Train and test a policy on a MIMo sample env (the reference's illustrations)");
  cmd->add_option("--env", o->env, "reach, standup, selfbody or catch")->required();
  cmd->add_option("--train_for,--steps", o->train_for, "Env steps of training (0: none)");
  cmd->add_option("--test_for", o->test_for, "Env steps of testing");
  cmd->add_option("--save_every", o->save_every, "Env steps between saved models");
  cmd->add_option("--algorithm,--algo", o->algorithm,
                  "PPO, SAC, TD3, DDPG or A2C (default: the --load_model checkpoint's; without "
                  "either, testing takes random actions)");
  cmd->add_option("--load_model", o->load_model, "Model checkpoint to start from");
  cmd->add_option("--save_model", o->save_model, "Name: models are saved in models/<env>/<name>");
  cmd->add_flag("--overwrite", o->overwrite, "Replace the models saved before under --save_model");
  cmd->add_flag("--render_video", o->render_video, "Film every test episode (episode_<i>.mp4)");
  cmd->add_flag("--use_muscles,--use_muscle", o->use_muscles,
                "Muscle actuation instead of spring-damper motors");
  cmd->add_flag("--stochastic", o->stochastic,
                "Test with sampled actions (SB3's predict default) instead of the policy's mean");
  cmd->add_flag("--jitter", o->jitter, "Catch: random action gains, redrawn every 10-50 steps");
  cmd->add_flag("--position_inaccurate", o->position_inaccurate,
                "Catch: per-episode error of the head's aim at the ball");
  cmd->add_flag("--palm_up", o->palm_up,
                "Catch: wrist pinned palm-up as in MIMo's first catch scene");
  cmd->add_option("--envs", o->envs, "Parallel training envs (one thread each)")
      ->check(CLI::Range(1, 1024));
  cmd->add_option("--seed", o->seed, "Seed of the envs and the learner")->check(kSeed);
  cmd->add_option("--hp", o->hp, "Hyperparameter override name=value (repeatable)");
  cmd->add_option(
      "--task-space", o->task_space,
      "Curriculum: task-space YAML whose teacher sets the training envs' reset options");
  cmd->add_option("--teacher", o->teacher, "Curriculum teacher (overrides the file's)");
  cmd->callback([o] { run(*o); });
}

}  // namespace cradle::apps

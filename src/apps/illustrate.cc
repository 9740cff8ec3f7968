// `cradle illustrate --env reach|standup|selfbody|catch [--train_for N] [--test_for M]
// [--algorithm PPO|SAC|TD3|DDPG|A2C] [--save_every K] [--save_model NAME] [--load_model PATH]
// [--use_muscles] [--render_video] [--stochastic] [--envs K] [--seed S] [--hp name=value]
// [--task-space FILE.yml [--teacher T]]`: the
// reference's illustrations.py. Trains a policy on a MIMo sample env (checkpoints
// models/<env>/<name>/model_<k>.ckpt every save_every steps; the run's logs/progress.csv with the
// training success rate, and plots/ with its learning curves),
// then runs test_for steps with it (or with random actions when there is no model), optionally
// filming each episode, and prints the success rate and the mean return per episode. Without
// --algorithm the algorithm is the --load_model checkpoint's; without either, testing takes
// random actions (training then needs --algorithm).
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "apps/cli_checks.h"
#include "apps/commands.h"
#include "apps/env_film.h"
#include "core/error.h"
#include "core/folders.h"
#include "core/rng.h"
#include "envs/mimo/sample_env.h"
#include "envs/registry.h"
#include "eval/video.h"
#include "learn/hyperparams.h"
#include "learn/registry.h"
#include "learn/vector_env.h"
#include "train/episodes.h"
#include "train/loop.h"
#include "train/run_policy.h"
#include "train/trainer.h"

namespace cradle::apps {
namespace {

namespace fs = std::filesystem;

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
  bool no_progress = false;
  int envs = 1;
  std::uint64_t seed = 0;
  std::vector<std::string> hp;
  std::string task_space, teacher;  // a curriculum (docs/curricula.md)
};

// The learner registry's name of an algorithm in any case (the reference's: PPO); HER, which the
// reference accepts but never uses, is not supported.
std::string learner_name(const std::string& algorithm) {
  std::string name = algorithm;
  std::ranges::transform(name, name.begin(), [](unsigned char c) { return std::tolower(c); });
  const std::vector<std::string>& names = learn::algorithm_names();
  if (std::ranges::find(names, name) != names.end()) return name;
  throw UserError(
      "--algorithm '" + algorithm + "'" +
      (name == "her" ? " is not supported (the reference accepts it but never uses it)" : "") +
      ": expected " + learn::algorithm_list() + " (in any case)");
}

// A copy of a file in the temp folder, removed with the object.
struct TempCopy {
  explicit TempCopy(const fs::path& file)
      : path(fs::temp_directory_path() /
             ("cradle-illustrate-" + std::to_string(::getpid()) + "-" + file.filename().string())) {
    std::error_code ec;
    fs::copy_file(file, path, fs::copy_options::overwrite_existing, ec);
    if (ec) throw UserError("--load_model '" + file.string() + "' cannot be read: " + ec.message());
  }
  ~TempCopy() {
    std::error_code ec;
    fs::remove(path, ec);
  }
  TempCopy(const TempCopy&) = delete;
  TempCopy& operator=(const TempCopy&) = delete;
  fs::path path;
};

void run(const IllustrateOptions& o) {
  // Flags first, before anything is built.
  const std::string id = envs::sample_env_id(o.env);
  // No --algorithm: the checkpoint's (--load_model), else none (testing with random actions).
  std::string algorithm = o.algorithm.empty() ? "" : learner_name(o.algorithm);
  if (algorithm.empty() && o.load_model.empty() && o.train_for > 0) {
    throw UserError("--train_for needs --algorithm (e.g. PPO) or --load_model");
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
  const fs::path dir = fs::path("models") / o.env / o.save_model;
  const bool trained_before = fs::exists(dir / "model_1.ckpt") || fs::exists(dir / "checkpoints") ||
                              fs::exists(dir / "progress.csv");  // an earlier version's layout
  if (o.train_for > 0 && !o.overwrite && trained_before) {
    throw UserError("'" + dir.string() +
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

  // The reference passes the actuation model explicitly: muscles only with --use_muscles.
  envs::EnvOptions env_options{{"actuation", o.use_muscles ? "muscle" : "spring_damper"}};
  if (o.jitter) env_options["jitter"] = "true";
  if (o.position_inaccurate) env_options["position_inaccurate"] = "true";
  if (o.palm_up) env_options["palm_up"] = "true";
  // The test env (made now, so that a bad option is refused before anything is written).
  const std::unique_ptr<envs::Env> env = envs::make_env(id, o.seed + 1000, env_options);
  if (!o.teacher.empty() && o.task_space.empty())
    throw UserError("--teacher needs --task-space FILE.yml (the parameters it sets)");

  // Training through the one run (train::train): the learner on a vector of envs sharing the
  // compiled scene, a curriculum when given, a model every save_every steps saved from the
  // progress report (one learn() call: episodes run on across saves, as the reference's
  // callback saves) and named model_<k>.ckpt, the run's progress bar, logs and curves.
  train::CheckpointLearner tested;  // the policy tested below (none: random actions)
  if (o.train_for > 0) {
    std::error_code ec;
    // A model of the folder that --overwrite clears is read from a copy taken first.
    std::optional<TempCopy> staged;
    if (!o.load_model.empty()) staged.emplace(o.load_model);
    // --overwrite: the earlier run's models go (and an earlier version's curves and logs; the
    // run replaces its own folders).
    if (o.overwrite) {
      for (const auto& entry : fs::directory_iterator(dir, ec)) {
        const std::string name = entry.path().filename().string();
        if (name.starts_with("model_") || name == "progress.csv" || name.ends_with(".png") ||
            name == "figures.json" || name == "teacher.jsonl")
          fs::remove(entry.path(), ec);
      }
    }
    const long first = staged ? learn::read_checkpoint_info(staged->path).steps : 0;
    int saved = 0;
    std::printf("training %s on %s for %ld steps (%d envs) -> %s\n", algorithm.c_str(), id.c_str(),
                o.train_for, o.envs, dir.c_str());
    std::fflush(stdout);
    train::TrainOptions to{.env = id,
                           .algorithm = algorithm,
                           .intrinsic = "",
                           .steps = first + o.train_for,
                           .envs = o.envs,
                           .threads = o.envs,
                           .seed = o.seed,
                           .overwrite = true,  // what --overwrite allows went above
                           .checkpoint_every = o.save_every,
                           .hyperparameters = hyperparameters,
                           .eval_episodes = 0,
                           .progress_bar = !o.no_progress,
                           .task_space = o.task_space,
                           .teacher = o.teacher};
    // Each saved checkpoint is also model_<k>.ckpt, the reference's name (a hard link).
    long saved_at = first;
    auto name_model = [&](const fs::path& checkpoint, long steps) {
      link_file(checkpoint, dir / ("model_" + std::to_string(++saved) + ".ckpt"));
      saved_at = steps;
    };
    to.on_checkpoint = [&](const fs::path& checkpoint) {
      const std::string stem = checkpoint.stem().string();  // step_<n>
      name_model(checkpoint, std::stol(stem.substr(stem.find('_') + 1)));
    };
    if (staged) to.load_model = staged->path.string();
    to.checkpoints_split_learning = false;
    Config config = default_config();
    config.save_dir = dir.string();
    const train::TrainResult trained = train::train(config, to);
    // The last model, when the budget ends between saves.
    if (trained.steps > saved_at) name_model(trained.checkpoint, trained.steps);
    std::printf("trained %ld steps in %.0f s; last model: %s\n", trained.steps - first,
                trained.seconds, (dir / ("model_" + std::to_string(saved) + ".ckpt")).c_str());
    if (!o.task_space.empty()) {
      std::printf("curriculum: training episodes booked in %s\n",
                  (dir / "logs" / "teacher.jsonl").c_str());
    }
    std::printf("progress: %s; learning curves: %s\n", (dir / "logs" / "progress.csv").c_str(),
                (dir / "plots").c_str());
    tested = train::load_learner(trained.checkpoint, id, env_options, hyperparameters, o.seed);
  } else if (!o.load_model.empty()) {
    tested = train::load_learner(o.load_model, id, env_options, hyperparameters, o.seed);
  }

  // Testing: one env, the policy's deterministic action (random actions without a model), one
  // rollout per episode until the step budget is spent; with --render_video a film per episode,
  // from the state after its reset.
  if (o.test_for == 0) return;
  const Box& space = env->action_space();
  Rng rng(o.seed + 2000);
  std::optional<EnvFilm> film;
  if (o.render_video) film.emplace(*env);
  std::optional<eval::VideoWriter> video;
  std::printf("testing %s for %ld steps with %s\n", id.c_str(), o.test_for,
              !tested.learner ? "random actions"
              : o.stochastic  ? "the trained policy (sampled actions)"
                              : "the trained policy");
  std::vector<train::EpisodeOutcome> episodes;
  learn::Learner* l = tested.learner.get();
  const train::EpisodePolicy policy{
      .act =
          [&](const envs::ObservationBuffers& obs, std::span<double> action) {
            if (l) {
              l->act(obs, action, /*deterministic=*/!o.stochastic);
            } else {
              space.sample(rng, action);
            }
          },
      .new_episode =
          [&] {
            if (l) l->new_episode();
            if (!film) return;
            std::error_code ec;
            fs::create_directories(dir, ec);
            video.emplace(dir / ("episode_" + std::to_string(episodes.size()) + ".mp4"),
                          film->width(), film->height(), film->fps());
            video->write(film->draw());
          }};
  bool ended = false;  // the last step ended its episode (not the budget)
  const auto on_step = [&](int, const envs::Env&, const envs::StepResult& r) {
    ended = r.terminated || r.truncated;
    if (video) video->write(film->draw());
  };
  // The first episode goes on from the env as made (reset with its seed again), the next ones
  // with its own stream, as the reference's test loop resets. An episode cut short by the end of
  // testing counts only when none ended.
  const std::uint64_t first_seed = o.seed + 1000;
  for (long left = o.test_for; left > 0;) {
    const train::EpisodeOutcome e =
        (episodes.empty() ? train::run_episodes(*env, policy, std::span(&first_seed, 1),
                                                static_cast<int>(left), on_step)
                          : train::run_episodes(*env, policy, 1, static_cast<int>(left), on_step))
            .front();
    if (video) video->close();
    left -= e.length;
    if (!ended) {
      if (episodes.empty()) episodes.push_back(e);
      break;
    }
    std::printf("  episode %zu: %d steps, return %.2f, %s\n", episodes.size(), e.length,
                e.episode_return, e.success ? "success" : "no success");
    episodes.push_back(e);
  }
  double returns = 0;
  int successes = 0;
  for (const train::EpisodeOutcome& e : episodes) {
    returns += e.episode_return;
    successes += e.success;
  }
  const double n = static_cast<double>(episodes.size());
  std::printf("%zu test episodes: success rate %.1f %% (%d/%zu), mean return %.3f\n",
              episodes.size(), 100.0 * successes / n, successes, episodes.size(), returns / n);
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
                  "Learner, in any case: " + learn::algorithm_list() +
                      " (default: the --load_model checkpoint's; without either, testing takes "
                      "random actions)");
  cmd->add_option("--load_model", o->load_model, "Model checkpoint to start from");
  cmd->add_option("--save_model", o->save_model, "Name: models are saved in models/<env>/<name>");
  cmd->add_flag("--overwrite", o->overwrite, "Replace the models saved before under --save_model");
  cmd->add_flag("--no-progress", o->no_progress, "No progress bar");
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

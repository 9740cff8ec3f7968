#include "train/run_policy.h"

#include <algorithm>
#include <system_error>
#include <utility>
#include <vector>

#include "core/error.h"
#include "envs/registry.h"
#include "learn/hyperparams.h"
#include "learn/learner.h"
#include "learn/registry.h"
#include "learn/vector_env.h"
#include "train/babybench_vector.h"
#include "train/env_vector.h"
#include "train/run_json.h"

namespace cradle::train {
namespace {

namespace fs = std::filesystem;

// What `cradle train` writes as run.json's env for a BabyBench config's run.
const char* const kBabyBenchConfigRun = "babybench config";

// The checkpoint names a run folder holds ("final", "latest", "step_4096"), for messages.
std::string held_checkpoints(const fs::path& folder) {
  std::vector<std::string> names;
  std::error_code ec;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->path().extension() == ".ckpt") names.push_back(it->path().stem().string());
  }
  if (names.empty()) return "none";
  std::sort(names.begin(), names.end());
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

}  // namespace

RunInfo read_run_info(const fs::path& run_folder) {
  std::error_code ec;
  if (!fs::is_directory(run_folder, ec)) {
    throw UserError("run folder '" + run_folder.string() +
                    (fs::exists(run_folder, ec) ? "' is not a folder" : "' does not exist") +
                    "; expected the folder of a `cradle train` run (it holds run.json)");
  }
  const RunJson j(run_folder / "run.json", "the run.json that `cradle train` writes");
  RunInfo run{.folder = run_folder};
  const std::string env = j.string("env");
  run.family = j.string("family");
  run.algorithm = j.string("algorithm");
  run.seed = j.unsigned_integer("seed");
  // Written by every `cradle train` since SaMI's learners keep per-env state; one env otherwise.
  if (j.has("envs")) {
    const long envs = j.positive_integer("envs");
    if (envs > 4096) {
      throw UserError(j.where() + ": \"envs\" is " + std::to_string(envs) +
                      "; expected a positive integer up to 4096");
    }
    run.envs = static_cast<int>(envs);
  }
  j.string_map("hyperparameters");  // checked: the checkpoint holds the values the run used
  const std::vector<std::string>& algorithms = learn::algorithm_names();
  if (std::find(algorithms.begin(), algorithms.end(), run.algorithm) == algorithms.end()) {
    throw UserError(j.where() + ": \"algorithm\" is \"" + run.algorithm + "\"; expected one of " +
                    learn::algorithm_list());
  }
  if (env == kBabyBenchConfigRun) {
    if (run.family != "babybench") {
      throw UserError(j.where() + ": \"family\" is \"" + run.family +
                      "\"; expected \"babybench\" for a BabyBench config's run");
    }
    const RunJson config = j.object("config");
    try {
      run.config = parse_config(config.json().dump(), j.where() + ": config");
    } catch (const UserError& e) {
      throw UserError(j.where() + ": \"config\" is not a BabyBench config (" + e.what() + ")");
    }
    return run;
  }
  try {
    run.env = envs::env_spec(env).id;
  } catch (const UserError& e) {
    throw UserError(j.where() + ": \"env\" is \"" + env + "\"; expected a registered env id (" +
                    e.what() + ")");
  }
  const std::string family = envs::env_spec(run.env).family;
  if (run.family != family) {
    throw UserError(j.where() + ": \"family\" is \"" + run.family + "\"; expected \"" + family +
                    "\", the family of " + run.env);
  }
  return run;
}

fs::path run_checkpoint_file(const fs::path& run_folder, const std::string& checkpoint) {
  if (checkpoint.empty()) {
    throw UserError("checkpoint is empty; expected final, latest, step_<n> or a .ckpt file");
  }
  const fs::path folder = run_folder / "checkpoints";
  // A bare name is one of the run's checkpoints; anything with a folder or .ckpt is a file.
  const bool named = checkpoint.find('/') == std::string::npos && !checkpoint.ends_with(".ckpt");
  const fs::path file = named ? folder / (checkpoint + ".ckpt") : fs::path(checkpoint);
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) {
    throw UserError("checkpoint '" + checkpoint + "' does not exist (" + file.string() +
                    "); expected one of the run's checkpoints (" + held_checkpoints(folder) +
                    ") or a .ckpt file");
  }
  return file;
}

RunPolicy::RunPolicy(RunInfo run, fs::path checkpoint, bool sampled,
                     std::shared_ptr<learn::VecEnv> spaces, std::shared_ptr<learn::Learner> learner)
    : run_(std::move(run)),
      checkpoint_(std::move(checkpoint)),
      sampled_(sampled),
      spaces_(std::move(spaces)),
      learner_(std::move(learner)) {}

long RunPolicy::steps() const { return learner_->steps(); }
const DictSpace& RunPolicy::observation_space() const { return spaces_->observation_space(); }
const Box& RunPolicy::action_space() const { return spaces_->action_space(); }

void RunPolicy::act(const envs::ObservationBuffers& observation, std::span<double> action) const {
  learner_->act(observation, action, /*deterministic=*/!sampled_);
}

void RunPolicy::new_episode() const { learner_->new_episode(); }

EpisodePolicy RunPolicy::episode_policy() const {
  // Copies of this policy share the learner, so the episode memory is the same one.
  return {.act = [p = *this](const envs::ObservationBuffers& observation,
                             std::span<double> action) { p.act(observation, action); },
          .new_episode = [p = *this] { p.new_episode(); }};
}

RunPolicy load_run_policy(const fs::path& run_folder, const std::string& checkpoint, bool sampled) {
  RunInfo run = read_run_info(run_folder);
  const fs::path file = run_checkpoint_file(run_folder, checkpoint);
  const learn::CheckpointInfo info = learn::read_checkpoint_info(file);
  if (info.algorithm != run.algorithm) {
    throw UserError("checkpoint " + file.string() + " holds a " + info.algorithm +
                    " learner, but " + (run_folder / "run.json").string() + " says " +
                    run.algorithm + "; expected a checkpoint of this run");
  }
  // The learner's spaces (and a SaMI learner's per-env state) come from a vector shaped like the
  // run's own; its envs are never stepped.
  std::shared_ptr<learn::VecEnv> vec =
      run.config
          ? std::shared_ptr<learn::VecEnv>(
                make_babybench_vec_env(*run.config, 1, 1, /*training=*/false, run.seed))
          : std::shared_ptr<learn::VecEnv>(make_env_training(run.env, run.envs, 1, run.seed).vec);
  const learn::LearnerOptions options{.hyperparameters =
                                          learn::parse_hyperparameter_text(info.config)};
  std::shared_ptr<learn::Learner> learner = learn::make_learner(info.algorithm, *vec, options);
  learner->load(file);
  return RunPolicy(std::move(run), file, sampled, std::move(vec), std::move(learner));
}

CheckpointLearner load_learner(const fs::path& checkpoint, const std::string& env_id,
                               const envs::EnvOptions& options,
                               const std::map<std::string, std::string>& overrides,
                               std::uint64_t seed) {
  const learn::CheckpointInfo info = learn::read_checkpoint_info(checkpoint);
  std::map<std::string, std::string> hyperparameters =
      learn::parse_hyperparameter_text(info.config);
  for (const auto& [name, value] : overrides) hyperparameters[name] = value;
  CheckpointLearner out;
  out.vec = make_env_training(env_id, 1, 1, seed, nullptr, 0, options).vec;
  out.learner = learn::make_learner(info.algorithm, *out.vec,
                                    {.seed = seed, .hyperparameters = hyperparameters});
  out.learner->load(checkpoint);
  return out;
}

train::Policy load_policy(const Config& config, const fs::path& checkpoint, bool sampled) {
  if (!fs::exists(checkpoint)) {
    throw UserError("policy checkpoint '" + checkpoint.string() + "' does not exist");
  }
  const learn::CheckpointInfo info = learn::read_checkpoint_info(checkpoint);
  // A one-env vector of the config gives the learner its spaces; it is kept alive by the policy.
  std::shared_ptr<learn::VecEnv> vec = make_babybench_vec_env(config, 1, 1, /*training=*/false, 0);
  learn::LearnerOptions lo{.hyperparameters = learn::parse_hyperparameter_text(info.config)};
  std::shared_ptr<learn::Learner> learner = learn::make_learner(info.algorithm, *vec, lo);
  learner->load(checkpoint);
  return [vec, learner, sampled](const envs::BabyBenchEnv& env, std::span<double> action) {
    learner->act(env.observation(), action, /*deterministic=*/!sampled);
  };
}

}  // namespace cradle::train

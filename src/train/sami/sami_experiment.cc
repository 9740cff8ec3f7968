#include "train/sami/sami_experiment.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/config.h"
#include "core/error.h"
#include "envs/registry.h"
#include "learn/hyperparams.h"
#include "learn/meta/sami_learner.h"
#include "learn/registry.h"
#include "sami/env.h"
#include "sami/task.h"
#include "train/env_vector.h"
#include "train/loop.h"
#include "train/run_json.h"
#include "train/trainer.h"

namespace cradle::train {
namespace {
namespace fs = std::filesystem;
}  // namespace

std::vector<sami::TaskSet> sami_training_sets(sami::EnvId id) {
  return sami::one_set_per_env(sami::split_sets(id, sami::Split::kTrain));
}

std::map<std::string, std::string> sami_presets(const envs::EnvSpec& env,
                                                const std::string& algorithm) {
  if (learn::meta::sami_method(algorithm).empty()) return {};
  std::map<std::string, std::string> presets;
  if (env.max_episode_steps > 0) {
    presets["horizon"] = std::to_string(env.max_episode_steps);
    presets["report_every"] = std::to_string(env.max_episode_steps);
  }
  // Panda's config (tma_sami.md §6).
  if (env.id.starts_with("sami/PandaPush:")) {
    presets["buffer_size"] = "1000";
    presets["batch_size"] = "256";
    presets["contrast_batch_size"] = "256";
  }
  return presets;
}

SamiRunFile read_sami_run(const fs::path& run) {
  const RunJson j(run / "run.json", "the run.json of a `cradle sami train` run");
  if (!j.has("algorithm") && j.has("method") && j.has("steps_per_env")) {
    throw UserError(j.where() +
                    " is an earlier `cradle sami train` run (checkpoint.ckpt beside progress.csv), "
                    "which this version does not read: train it again into a new folder");
  }
  SamiRunFile r{.env_id = j.string("env"),
                .algorithm = j.string("algorithm"),
                .seed = j.unsigned_integer("seed"),
                .envs = j.positive_integer("envs"),
                .hyperparameters = j.string_map("hyperparameters")};
  r.steps = j.positive_integer("steps");
  const std::string family = j.string("family");
  // A run of another family or learner names the file it came from.
  if (family != "sami" || !r.env_id.starts_with("sami/")) {
    throw UserError(j.where() + ": env '" + r.env_id + "' is not a SaMI env (expected sami/<Env>)");
  }
  r.method = std::string(learn::meta::sami_method(r.algorithm));
  if (r.method.empty()) {
    throw UserError(j.where() + ": algorithm '" + r.algorithm +
                    "' is not one of SaMI's learners (expected " +
                    learn::meta::sami_learner_list() + ")");
  }
  r.env = envs::split_env_id(r.env_id).name;
  try {
    sami::env_from_name(r.env);
  } catch (const UserError& e) {
    throw UserError(j.where() + ": " + e.what());
  }
  r.steps_per_env = (r.steps + r.envs - 1) / r.envs;
  return r;
}

SamiTrainResult sami_train(const SamiTrainOptions& options) {
  // The run's settings: fresh from the options, or on --resume from run.json. A folder that holds
  // a run is refused without --resume or --overwrite, which clears it (the run's rule; SaMI's
  // evaluations and an earlier version's files are the family's outputs, train/families.h).
  if (options.out.empty() && (options.env.empty() || options.method.empty())) {
    throw UserError("sami train: give the run folder (--out) or the env and the method");
  }
  if (options.resume && options.overwrite)
    throw UserError("sami train: --resume and --overwrite: give one of them");
  const fs::path run = options.out.empty()
                           ? fs::path("runs/sami") / (options.env + "_" + options.method + "_" +
                                                      std::to_string(options.seed))
                           : options.out;
  std::string env_name = options.env, method = options.method;
  std::uint64_t seed = options.seed;
  long steps_per_env = options.steps_per_env;
  if (options.resume) {
    const SamiRunFile saved = read_sami_run(run);
    // A resumed run keeps its env and method: one given that contradicts them is refused, not
    // ignored.
    const auto keep = [&](const std::string& given, const std::string& kept, const char* flag) {
      if (!given.empty() && given != kept) {
        throw UserError("sami train --resume: " + (run / "run.json").string() + " is a run of " +
                        flag + " " + kept + ", not " + flag + " " + given + " (leave " + flag +
                        " out to continue it)");
      }
    };
    keep(options.env, saved.env, "--env");
    keep(options.method, saved.method, "--method");
    // A `cradle train` run on another split or vector continues there, not on SaMI's sets.
    const std::string ours = "sami/" + saved.env + ":train";
    if (saved.env_id != ours ||
        saved.envs !=
            static_cast<long>(sami_training_sets(sami::env_from_name(saved.env)).size())) {
      throw UserError("sami train --resume: " + (run / "run.json").string() + " is a run of " +
                      saved.env_id + " on " + std::to_string(saved.envs) +
                      " envs, not of SaMI's training sets: continue it with `cradle train --env " +
                      saved.env_id + " --save-dir " + run.string() + " --resume`");
    }
    env_name = saved.env;
    method = saved.method;
    seed = saved.seed;
    if (steps_per_env == 0) steps_per_env = saved.steps_per_env;
  }
  if (options.steps < 0) throw UserError("sami train: --steps must be positive");
  const sami::EnvId id = sami::env_from_name(env_name);
  const std::string algorithm = learn::meta::sami_learner_name(method);
  const long envs = static_cast<long>(sami_training_sets(id).size());
  if (options.steps > 0) steps_per_env = (options.steps + envs - 1) / envs;
  if (steps_per_env == 0) steps_per_env = id == sami::EnvId::kPandaPush ? 1'000'000 : 500'000;
  if (steps_per_env < 0) throw UserError("sami train: --steps-per-env must be positive");
  if (options.checkpoint_every < 1)
    throw UserError("sami train: checkpoint_every must be positive");
  if (options.report_every < 0) throw UserError("sami train: report_every must be positive");

  // SaMI's settings come with `cradle train`'s presets for its learners (sami_presets); a
  // resumed run keeps its checkpoint's. The user's go over them.
  std::map<std::string, std::string> hp = options.hyperparameters;
  if (options.report_every > 0)
    hp.try_emplace("report_every", std::to_string(options.report_every));

  Config config;
  config.save_dir = run.string();
  SamiTrainResult result{.run = run, .checkpoint = run / "checkpoints" / "final.ckpt"};
  long window_updates = 0;
  double update_seconds = 0;
  const TrainResult trained =
      train(config, {.env = "sami/" + env_name + ":train",
                     .algorithm = algorithm,
                     .intrinsic = "",
                     .steps = steps_per_env * envs,
                     .envs = static_cast<int>(envs),
                     .threads = 1,  // SaMI's envs step one after the other (its DummyVecEnv)
                     .seed = seed,
                     .resume = options.resume,
                     .overwrite = options.overwrite,
                     .checkpoint_every = options.checkpoint_every * envs,
                     .hyperparameters = hp,
                     .eval_episodes = 0,
                     .progress_bar = options.progress_bar,
                     .stop = options.stop,
                     .on_report =
                         [&](const learn::TrainStats& s) {
                           const auto loss = [&](const char* key) {
                             const auto it = s.losses.find(key);
                             return it == s.losses.end() ? 0.0 : it->second;
                           };
                           result.updates = static_cast<long>(loss("updates"));
                           window_updates += static_cast<long>(loss("gradient_steps"));
                           update_seconds += loss("update_seconds");
                           if (s.episodes > 0) result.last_return = s.episodic_return;
                         },
                     .sync = options.sync});
  result.steps = trained.steps;
  result.parameter_hash = trained.parameter_hash;
  result.sps = trained.steps_per_second;
  result.gradient_steps_per_s = update_seconds > 0 ? window_updates / update_seconds : 0;
  result.stopped = options.stop && options.stop->load() && result.steps < steps_per_env * envs;
  return result;
}

}  // namespace cradle::train

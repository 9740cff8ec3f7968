// The trained policy of a run, found by its folder: run.json says which env, family and
// algorithm the run trained, checkpoints/<name>.ckpt holds the learner. This is the one front
// door for `cradle evaluate --run DIR` and Python's cradle.load_policy(run_folder), for runs of
// every family (`cradle train --env ID`, cradle.train(env=...)) and BabyBench configs alike. A
// bare checkpoint's learner or policy (`cradle illustrate --load_model`, `cradle evaluate
// --policy`) is loaded here too.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <span>
#include <string>

#include "core/config.h"
#include "core/spaces.h"
#include "envs/env.h"
#include "envs/registry.h"
#include "train/episodes.h"
#include "train/evaluation.h"

namespace cradle::learn {
class Learner;
class VecEnv;
}  // namespace cradle::learn

namespace cradle::train {

// What run.json says about a run, every key checked.
struct RunInfo {
  std::filesystem::path folder;
  // The registered env id the run trained on; empty for a BabyBench config's run.
  std::string env;
  std::string family;  // "babybench", "mimo", "tma" or "sami"
  std::string algorithm;
  std::uint64_t seed = 0;
  int envs = 1;  // envs per rank: SaMI's learners keep per-env state in their checkpoints
  std::optional<Config> config;  // a BabyBench config's run: its config
};

// Reads <run_folder>/run.json. A missing or damaged file, a missing key or a value of another
// type is a one-line UserError naming the file, the key and what was expected.
RunInfo read_run_info(const std::filesystem::path& run_folder);

// The checkpoint file that `checkpoint` names in a run: "final", "latest", "step_<n>" (files of
// <run>/checkpoints/) or a path to a .ckpt file. UserError naming what the folder holds when it
// does not exist.
std::filesystem::path run_checkpoint_file(const std::filesystem::path& run_folder,
                                          const std::string& checkpoint);

// A run's trained policy. Copies share one learner (its episode memory included).
class RunPolicy {
 public:
  RunPolicy(RunInfo run, std::filesystem::path checkpoint, bool sampled,
            std::shared_ptr<learn::VecEnv> spaces, std::shared_ptr<learn::Learner> learner);

  const RunInfo& run() const { return run_; }
  const std::filesystem::path& checkpoint() const { return checkpoint_; }
  // The checkpoint's name: its file name without .ckpt ("final", "latest", "step_4096").
  std::string checkpoint_name() const { return checkpoint_.stem().string(); }
  bool sampled() const { return sampled_; }
  long steps() const;  // env steps the checkpoint was trained for
  const DictSpace& observation_space() const;
  const Box& action_space() const;

  // The action for one observation of the run's env: the policy's mean, or with `sampled` a
  // draw from its distribution by the checkpoint's own generator.
  void act(const envs::ObservationBuffers& observation, std::span<double> action) const;
  // The next observation starts a new episode (a policy with memory forgets the last one).
  void new_episode() const;
  // For train::run_episodes.
  EpisodePolicy episode_policy() const;
  // The learner itself (e.g. to read a SaMI learner's last context).
  const learn::Learner& learner() const { return *learner_; }

 private:
  RunInfo run_;
  std::filesystem::path checkpoint_;
  bool sampled_ = false;
  // A vector of the run's env: the learner was built on it and reads its spaces.
  std::shared_ptr<learn::VecEnv> spaces_;
  std::shared_ptr<learn::Learner> learner_;
};

// The policy of a run folder's checkpoint (see run_checkpoint_file): the env's spaces rebuilt
// from the registry (or the run's BabyBench config), the learner from the checkpoint's own
// algorithm and hyperparameters. Deterministic (the mean action) unless `sampled`.
RunPolicy load_run_policy(const std::filesystem::path& run_folder,
                          const std::string& checkpoint = "final", bool sampled = false);

// A checkpoint's learner on a one-env vector of an env id (kept with it, the learner acts on it),
// e.g. to test a trained policy on an env of its own: the checkpoint's hyperparameters with
// `overrides` over them, seeded `seed` (a checkpoint that restores its generator overrides it).
struct CheckpointLearner {
  std::shared_ptr<learn::VecEnv> vec;
  std::shared_ptr<learn::Learner> learner;
};
CheckpointLearner load_learner(const std::filesystem::path& checkpoint, const std::string& env_id,
                               const envs::EnvOptions& options = {},
                               const std::map<std::string, std::string>& overrides = {},
                               std::uint64_t seed = 0);

// The policy of a checkpoint, for `cradle evaluate --policy`: the mean action, or with `sampled`
// actions drawn from the policy's distribution (as SB3's predict() does by default) by the
// checkpoint's own generator, so a sampled evaluation of one checkpoint repeats exactly.
train::Policy load_policy(const Config& config, const std::filesystem::path& checkpoint,
                          bool sampled = false);

}  // namespace cradle::train

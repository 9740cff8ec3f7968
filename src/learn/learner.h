// The common interface of Cradle's learners, so the CLI can drive any algorithm. This header
// does not include LibTorch: only the learners' own files do.
//
// A learner owns its networks, optimiser, observation normaliser and random generator, and
// trains on a VecEnv it borrows (the env must outlive the learner). Every learn() call starts
// fresh episodes (the envs are reset with a seed drawn from the learner's generator), so a run
// that is saved, loaded into a new learner and continued behaves exactly like the original
// learner continuing from the same save point.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "envs/env.h"
#include "learn/vec_env.h"

namespace cradle::learn {

class GradSync;  // learn/grad_sync.h

// Progress, reported after every rollout and its update (off-policy: every report_every steps).
struct TrainStats {
  long steps = 0;    // env steps so far (vector steps x num_envs), counting earlier runs resumed
  double sps = 0;    // env steps per second in this learn() call (collection and update)
  int episodes = 0;  // episodes that ended since the last report
  // Mean return and length of those episodes (NaN when none ended). The return is the sum of
  // the rewards the learner trained on: env reward plus whatever the reward hook added.
  double episodic_return = std::numeric_limits<double>::quiet_NaN();
  double episodic_length = std::numeric_limits<double>::quiet_NaN();
  // Losses and diagnostics of the last update(s), by name: "policy_loss", "value_loss",
  // "entropy", "approx_kl", "clip_fraction", "explained_variance", "learning_rate", "std", ...
  // for PPO and A2C; "qf_loss", "qf1_loss", "qf1_values", "actor_loss", "alpha", "alpha_loss"
  // (CleanRL's names), means over the updates since the last report, for SAC, TD3 and DDPG;
  // "qf_loss", "actor_loss", "alpha", "alpha_loss", "entropy", "sance_loss", "sance_weight" for
  // SaMI's context learners (learn/meta/sami_learner.h).
  std::map<std::string, double> losses;
};

// Returns false to stop training after this report.
using ProgressFn = std::function<bool(const TrainStats&)>;

// Reward hook, for intrinsic rewards: called after every vector step with the env (its
// observations, flags and infos are those of the step just taken), the actions sent to it
// (num_envs x action dim, row-major, clipped to the action bounds) and the env rewards, which it
// may change in place (e.g. add an intrinsic reward). The learner trains on the changed
// rewards. Envs that were autoreset by this step (Gymnasium next-step autoreset) report reward 0
// and their entry is discarded whatever the hook writes.
using RewardHook = std::function<void(const VecEnv& env, std::span<const double> actions,
                                      std::span<double> rewards)>;

struct LearnerOptions {
  std::uint64_t seed = 0;  // seeds network initialisation, action sampling, minibatches, resets
  // Overrides of the algorithm's hyperparameters by name, e.g. {"n_steps", "512"}; values are
  // text, parsed strictly. Besides the algorithm's own (see PpoConfig, A2cConfig, SacConfig,
  // Td3Config, OffPolicyConfig) every learner takes the observation settings
  // (ObservationConfig: normalize_observations, clip_observations, pool_touch) and the network
  // settings (PolicyConfig for PPO and A2C: pi_layers, vf_layers, activation, cnn_features,
  // ortho_init, log_std_init; OffPolicyNetworkConfig for SAC, TD3 and DDPG: pi_layers,
  // qf_layers, activation, cnn_features). SaMI's context learners take theirs only (SamiConfig
  // and SamiLearnerConfig, learn/meta/sami_learner.h).
  std::map<std::string, std::string> hyperparameters;
  RewardHook reward_hook;      // optional
  std::string device = "cpu";  // only "cpu" for now
  // LibTorch intra-op threads (a process-wide setting); 0 leaves it as it is. One thread is the
  // fastest for these small networks while the envs keep the other cores busy.
  int torch_threads = 1;
  // LibTorch threads during gradient updates, while the envs wait. 0: every core for policies
  // with image inputs, whose convolutions scale, and torch_threads for vector-only policies.
  int update_threads = 0;
  // A data-parallel run's ranks (learn/grad_sync.h); null: this process trains alone. PPO, A2C
  // and SAC average their gradients over it and merge their observation statistics.
  std::shared_ptr<GradSync> sync;
};

class Learner {
 public:
  virtual ~Learner() = default;
  // "ppo", "a2c", "sac", "td3", "ddpg", ... (learn/registry.h algorithm_names()).
  virtual std::string_view algorithm() const = 0;
  // Trains until steps() >= total_steps (whole rollouts, so it may overshoot by less than one
  // rollout; off-policy learners: whole vector steps), reporting after each update (off-policy
  // learners: every report_every vector steps and at the end); stops early when on_progress
  // returns false.
  virtual void learn(long total_steps, const ProgressFn& on_progress) = 0;
  // Env steps trained on so far (restored by load).
  virtual long steps() const = 0;
  // Writes a checkpoint: networks, optimiser, observation normaliser, config text, random
  // generator state and step counter, atomically (temp file + rename).
  virtual void save(const std::filesystem::path& file) const = 0;
  // Restores everything save wrote. Throws UserError for a missing or unreadable file, another
  // algorithm's checkpoint, other observation settings (normalize_observations,
  // clip_observations, pool_touch) or networks of another shape; these are checked before
  // anything changes. Other hyperparameters come from the options the learner was built with
  // (CheckpointInfo::config has the saved ones).
  virtual void load(const std::filesystem::path& file) = 0;
  // The action for one observation (e.g. for evaluation), clipped to the action bounds: the
  // Gaussian's mean when deterministic, else a sample from the learner's generator. Does not
  // update the observation statistics.
  virtual void act(const envs::ObservationBuffers& observation, std::span<double> action,
                   bool deterministic) = 0;
  // Tells act() that its next observation starts a new episode. A learner whose actions depend
  // on the episode so far (SaMI's context learners, learn/meta/sami_learner.h) restarts that
  // memory; the others have none and ignore it.
  virtual void new_episode() {}
  // The expected discounted return from one observation (curriculum teachers' estimate, SPDL):
  // PPO's value head, SAC's min_i Q_i(s, tanh(mean(s))), TD3's and DDPG's min_i Q_i(s, mu(s));
  // NaN for a learner without one. Does not update the observation statistics.
  virtual double value(const envs::ObservationBuffers& /*observation*/) {
    return std::numeric_limits<double>::quiet_NaN();
  }
  // Every hyperparameter as "name = value" lines (what checkpoints store).
  virtual std::string config_text() const = 0;
  // A hash of the trained parameters (learn/grad_sync.h tensor_hash), equal on every rank of a
  // data-parallel run; 0 when the learner does not compute one.
  virtual std::uint64_t parameter_hash() const { return 0; }
};

// What a checkpoint says about itself, read without building a learner (e.g. to pick the
// algorithm and hyperparameters for --resume: parse_hyperparameter_text(info.config)).
struct CheckpointInfo {
  std::string algorithm;
  std::string config;  // "name = value" lines
  long steps = 0;
};
CheckpointInfo read_checkpoint_info(const std::filesystem::path& file);

}  // namespace cradle::learn

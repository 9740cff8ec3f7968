// On-policy experience: the rollout buffer, generalised advantage estimation, and the collector
// that runs a Gaussian policy in a VecEnv.
//
// Next-step autoreset and the buffer. The VecEnv reports an episode's final observation on the
// step that ends it, and resets that env on the following call (reward 0, action ignored). So:
// - the observation after a done step is the final observation, and the value the collector
//   computes for it at the next step is exactly the bootstrap value a truncated episode needs
//   (V of the final observation); a terminated episode bootstraps nothing;
// - the autoreset step itself is no transition: it is stored with valid = 0 and left out of
//   every loss.
// For buffer row t (per env): next value = V(row t + 1), or last_values after the last row.
#pragma once

#include <torch/torch.h>

#include <cstdint>
#include <span>
#include <vector>

#include "core/spaces.h"
#include "learn/learner.h"
#include "learn/networks.h"
#include "learn/preprocess.h"
#include "learn/vec_env.h"
#include "learn/vector_env.h"

namespace cradle::learn {

// Generalised advantage estimation (Schulman et al. 2016) over [steps][envs] arrays, row-major:
//   delta_t = r_t + gamma (1 - terminated_t) V_{t+1} - V_t
//   A_t     = delta_t + gamma lambda (1 - done_t) A_{t+1}
//   R_t     = A_t + V_t  (the value target)
// where V_{t+1} is values[t + 1] and, after the last step, last_values; done = terminated or
// truncated. A truncated step thus bootstraps from V_{t+1}, the final observation's value.
void compute_gae(int steps, int envs, std::span<const float> rewards, std::span<const float> values,
                 std::span<const float> last_values, std::span<const std::uint8_t> terminated,
                 std::span<const std::uint8_t> dones, double gamma, double gae_lambda,
                 std::span<float> advantages, std::span<float> returns);

// One rollout: steps x envs transitions, flattened with row = step * envs + env.
struct RolloutBuffer {
  RolloutBuffer(int steps, int envs, const ObsShape& shape, int action_size);
  int rows() const { return steps * envs; }
  // Fills advantages and returns from rewards, values, last_values and the flags.
  void compute_returns_and_advantages(double gamma, double gae_lambda);
  // Rows with valid == 1 (int64).
  torch::Tensor valid_rows() const;

  int steps, envs;
  ObsBatch observations;    // the observation each action was taken in (normalised)
  torch::Tensor actions;    // [rows, action_size] float32, unclipped Gaussian samples
  torch::Tensor log_probs;  // [rows] float32, log pi(action | observation) when sampled
  torch::Tensor values;     // [rows] float32, V(observation) when sampled
  torch::Tensor rewards;    // [rows] float32, after the reward hook
  torch::Tensor terminated, dones, valid;  // [rows] uint8
  torch::Tensor last_values;               // [envs] float32, V(observation after the rollout)
  torch::Tensor advantages, returns;       // [rows] float32
};

// Completed episodes, for TrainStats.
class EpisodeStats {
 public:
  void reset(int envs);
  void add(int env, double reward);  // one step of env's current episode
  void end(int env);                 // env's episode ended
  // The episodes ended since the last report into a learner's report (their count, mean return
  // and length; NaN when none ended), then forgotten.
  void report_into(TrainStats& stats);

 private:
  std::vector<double> returns_;
  std::vector<int> lengths_;
  double sum_return_ = 0, sum_length_ = 0;
  int ended_ = 0;
};

// Steps a VecEnv for a learner: applies the reward hook and follows next-step autoreset, telling
// which entries of a step are real transitions (an env reset by the step has none) and tallying
// the episodes they complete. Shared by the on-policy and off-policy collectors.
class EnvStepper {
 public:
  EnvStepper(VecEnv& env, RewardHook reward_hook);
  // Starts fresh episodes: resets every env with `seed`.
  void start(std::uint64_t seed);
  // Sends actions (num_envs x action dim, within the bounds) and applies the reward hook.
  void step(std::span<const double> actions);
  // Of the last step: the rewards to train on (env reward plus the hook's), and per env 1 for a
  // real transition, 0 for an autoreset.
  std::span<const double> rewards() const { return rewards_; }
  std::span<const std::uint8_t> real() const { return real_; }
  EpisodeStats& episodes() { return episodes_; }

 private:
  VecEnv& env_;
  RewardHook reward_hook_;
  std::vector<double> rewards_;
  std::vector<std::uint8_t> pending_;  // env ended its episode; the next step autoresets it
  std::vector<std::uint8_t> real_;
  EpisodeStats episodes_;
};

// Runs a GaussianActorCritic in a VecEnv and fills rollout buffers.
//
// Given an AsyncVecEnv it collects through send/recv (no lock-step): each env fills its own rows
// (row = its step in this rollout x envs + env id, so GAE sees per-env sequences as before) at its
// own pace; an env that has filled buffer.steps rows is held until the next rollout, and the
// value of its observation then is its last value. Observation statistics and action noise are
// taken in batch order, which timing decides, so such runs are not bitwise repeatable. The reward
// hook sees each batch as a VecEnv of its own (BatchView: env j is the batch's j-th env id) with
// the batch's actions and rewards, so a hook that keeps per-env state indexes it by
// VecEnv::env_id (as the intrinsic rewards do).
class RolloutCollector {
 public:
  RolloutCollector(VecEnv& env, ObservationPipeline& pipeline, RewardHook reward_hook);
  // Starts fresh episodes: resets every env with `seed` and reads the first observations.
  void start(std::uint64_t seed);
  // buffer.steps vector steps: sample actions (unclipped into the buffer, clipped to the action
  // bounds for the env), step, apply the reward hook, record flags, normalise the next
  // observations (updating the statistics); then the values of the last observations.
  void collect(GaussianActorCritic& policy, at::Generator& generator, RolloutBuffer& buffer);
  EpisodeStats& episodes() { return stepper_.episodes(); }

 private:
  void collect_async(GaussianActorCritic& policy, at::Generator& generator, RolloutBuffer& buffer);

  VecEnv& env_;
  ObservationPipeline& pipeline_;
  EnvStepper stepper_;
  ObsBatch observation_;  // current normalised observations, one row per env
  torch::Tensor noise_;   // [envs, action_size]
  std::vector<double> actions_;
  // Async collection: the env's async face (null in lock-step), every env id, per env its rows
  // filled this rollout and whether its next step is an autoreset, and a batch's scratch.
  AsyncVecEnv* async_ = nullptr;
  std::vector<int> all_ids_, filled_;
  std::vector<std::uint8_t> pending_;
  ObsBatch batch_observation_;
  torch::Tensor batch_noise_;
  std::vector<int> send_ids_;
  std::vector<double> send_actions_;
  RewardHook reward_hook_;
  std::vector<double> sent_actions_;                 // per env: its last action (clipped)
  std::vector<double> hook_actions_, hook_rewards_;  // a batch's, for the hook
};

// Writes actions[i] = clamp(samples[i], low[i], high[i]) (doubles, row-major).
void clip_actions(const torch::Tensor& samples, const Box& bounds, std::span<double> actions);

// One action for one observation (Learner::act for Gaussian policies): the mean when
// deterministic, else a sample; clipped to the bounds. `scratch` is a 1-row batch.
void act_gaussian(ObservationPipeline& pipeline, GaussianActorCritic& policy,
                  at::Generator& generator, const Box& bounds,
                  const envs::ObservationBuffers& observation, ObsBatch& scratch,
                  std::span<double> action, bool deterministic);

}  // namespace cradle::learn

// Advantage Actor-Critic: the synchronous variant of A3C (Mnih et al. 2016, "Asynchronous
// Methods for Deep Reinforcement Learning"), as in Stable-Baselines3's A2C: short rollouts, one
// RMSprop step per rollout. Defaults are SB3's.
#pragma once

#include <memory>

#include "learn/hyperparams.h"
#include "learn/learner.h"

namespace cradle::learn {

struct A2cConfig {
  double learning_rate = 7e-4;  // RMSprop step size
  // Decay the learning rate linearly to 0 over learn()'s total_steps (SB3: a linear schedule
  // passed as learning_rate). Off = SB3's constant default.
  bool anneal_lr = false;
  int n_steps = 5;                   // vector steps per env per rollout (and per update)
  double gamma = 0.99;               // discount factor
  double gae_lambda = 1.0;           // 1 = plain n-step returns, as A2C
  double ent_coef = 0.0;             // entropy bonus weight
  double vf_coef = 0.5;              // value loss weight
  double max_grad_norm = 0.5;        // global gradient norm clip
  double rms_prop_alpha = 0.99;      // RMSprop smoothing constant (SB3 alpha in policy_kwargs)
  double rms_prop_eps = 1e-5;        // RMSprop epsilon (SB3 rms_prop_eps)
  bool normalize_advantage = false;  // standardise advantages over the rollout
  // Collect rollout k+1 on a thread of its own while updating on rollout k (learn/on_policy.h),
  // as PPO's; with A2C's 5-step rollouts the thread handoff costs about what it saves.
  bool overlap_update = false;

  void bind(Hyperparameters& table);
};

// An A2C learner on `env` (which must outlive it). Throws UserError for bad options.
std::unique_ptr<Learner> make_a2c(VecEnv& env, const LearnerOptions& options);

}  // namespace cradle::learn

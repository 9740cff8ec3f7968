// Proximal Policy Optimization (Schulman et al. 2017, "Proximal Policy Optimization
// Algorithms"), clipped-surrogate variant with GAE, as in Stable-Baselines3's PPO. Defaults are
// SB3's; the comment after each field gives SB3's name where it differs or needs saying.
#pragma once

#include <memory>

#include "learn/hyperparams.h"
#include "learn/learner.h"

namespace cradle::learn {

struct PpoConfig {
  double learning_rate = 3e-4;  // Adam step size
  // Decay the learning rate linearly to 0 over learn()'s total_steps (SB3: a linear schedule
  // passed as learning_rate; CleanRL anneal_lr). Off = SB3's constant default.
  bool anneal_lr = false;
  int n_steps = 2048;        // vector steps per env per rollout (rollout = n_steps x num_envs)
  int batch_size = 64;       // minibatch size
  int n_epochs = 10;         // passes over each rollout
  double gamma = 0.99;       // discount factor
  double gae_lambda = 0.95;  // GAE lambda (bias-variance trade-off of the advantage)
  double clip_range = 0.2;   // epsilon of the clipped surrogate: ratio kept in [1-eps, 1+eps]
  // Clip the value prediction to within this of the old value; <= 0 disables it (SB3
  // clip_range_vf=None).
  double clip_range_vf = 0.0;
  bool normalize_advantage = true;  // standardise advantages per minibatch
  double ent_coef = 0.0;            // entropy bonus weight
  double vf_coef = 0.5;             // value loss weight
  double max_grad_norm = 0.5;       // global gradient norm clip
  // Stop an update's epochs early once the approximate KL exceeds 1.5 x target_kl; <= 0
  // disables it (SB3 target_kl=None).
  double target_kl = 0.0;
  double adam_eps = 1e-5;  // Adam epsilon (SB3 sets 1e-5 for its policies' Adam)
  // Train on rewards divided by the running std of the discounted return, clipped to +-10
  // (VecNormalize norm_reward; learn/return_normalizer.h). Its statistics are checkpointed.
  bool normalize_returns = false;
  // Collect rollout k+1 on a thread of its own while updating on rollout k (learn/on_policy.h):
  // rollouts act with the policy one update old, each iteration takes max(collect, update)
  // instead of their sum. Deterministic for a seed and env count; off = SB3's loop.
  bool overlap_update = false;

  void bind(Hyperparameters& table);
};

// A PPO learner on `env` (which must outlive it). Throws UserError for bad options.
std::unique_ptr<Learner> make_ppo(VecEnv& env, const LearnerOptions& options);

}  // namespace cradle::learn

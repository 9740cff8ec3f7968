// Soft Actor-Critic (Haarnoja et al. 2018, "Soft Actor-Critic Algorithms and Applications"):
// a tanh-squashed Gaussian policy maximising return plus entropy, twin Q critics with Polyak
// target copies, and the temperature alpha tuned automatically towards a target entropy, as in
// Stable-Baselines3's SAC. Defaults are SB3's; the comment after each field gives SB3's name
// where it differs or needs saying.
#pragma once

#include <memory>
#include <string>

#include "learn/hyperparams.h"
#include "learn/learner.h"
#include "learn/off_policy.h"

namespace cradle::learn {

struct SacConfig {
  // Temperature alpha: "auto" (learned, starting at 1), "auto_<init>" (learned, starting at
  // init) or a number (fixed).
  std::string ent_coef = "auto";
  // Entropy the learned temperature aims at: "auto" (-action dimensions) or a number.
  std::string target_entropy = "auto";
  int target_update_interval = 1;  // gradient steps between target updates
  int n_critics = 2;               // Q networks; targets take their minimum (clipped double Q)
  void bind(Hyperparameters& table);
};

// The loop's SB3 defaults for SAC: learning_rate 3e-4, buffer_size 1e6, learning_starts 100,
// batch_size 256, tau 0.005, gamma 0.99, train_freq 1, gradient_steps 1.
OffPolicyConfig sac_loop_defaults();

// A SAC learner on `env` (which must outlive it). Throws UserError for bad options, an action
// space without finite bounds, or a replay buffer too large for the machine.
std::unique_ptr<Learner> make_sac(VecEnv& env, const LearnerOptions& options);

}  // namespace cradle::learn

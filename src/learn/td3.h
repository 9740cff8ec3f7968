// Twin Delayed DDPG (Fujimoto et al. 2018, "Addressing Function Approximation Error in
// Actor-Critic Methods"): a deterministic tanh actor explored with Gaussian noise, twin Q
// critics whose minimum makes the target (clipped double Q), target policy smoothing noise, and
// actor and target updates delayed to every policy_delay critic updates, as in
// Stable-Baselines3's TD3. Defaults are SB3's (2.3 and later); the comment after each field
// gives SB3's name where it differs or needs saying.
#pragma once

#include <memory>
#include <string_view>

#include "learn/hyperparams.h"
#include "learn/learner.h"
#include "learn/off_policy.h"

namespace cradle::learn {

struct Td3Config {
  int policy_delay = 2;              // critic updates per actor and target update
  double target_policy_noise = 0.2;  // std of the smoothing noise on target actions ([-1, 1] scale)
  double target_noise_clip = 0.5;    // the smoothing noise is clipped to +-this
  // Std of the Gaussian exploration noise on the actor's actions ([-1, 1] scale). SB3's default
  // is no noise (action_noise=None); its examples and the paper use N(0, 0.1).
  double exploration_noise = 0.1;
  int n_critics = 2;  // Q networks; targets take their minimum
  // DDPG (SB3's DDPG is TD3 with these fixed): one critic, policy_delay 1, no smoothing noise;
  // the fixed settings are then left out of the hyperparameter table. Not a hyperparameter.
  bool ddpg = false;
  void bind(Hyperparameters& table);
};

// The loop's SB3 (>= 2.3) defaults for TD3 and DDPG: learning_rate 1e-3, buffer_size 1e6,
// learning_starts 100, batch_size 256, tau 0.005, gamma 0.99, train_freq 1, gradient_steps 1.
// (Before 2.3 SB3 used batch_size 100, train_freq one episode, gradient_steps -1 and 400-300
// networks.)
OffPolicyConfig td3_loop_defaults();

// A TD3 learner on `env` (which must outlive it). Throws UserError for bad options, an action
// space without finite bounds, or a replay buffer too large for the machine.
std::unique_ptr<Learner> make_td3(VecEnv& env, const LearnerOptions& options);

// The TD3 machinery under another name and defaults (DDPG).
std::unique_ptr<Learner> make_td3_variant(std::string_view algorithm, VecEnv& env,
                                          const LearnerOptions& options, const Td3Config& own);

}  // namespace cradle::learn

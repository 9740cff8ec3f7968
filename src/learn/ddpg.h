// Deep Deterministic Policy Gradient (Lillicrap et al. 2016, "Continuous control with deep
// reinforcement learning") as Stable-Baselines3 implements it: the TD3 machinery (td3.h) with
// one critic, the actor and targets updated at every critic update and no target policy
// smoothing. Gaussian exploration noise (std 0.1) instead of the paper's Ornstein-Uhlenbeck
// process, as SB3's examples and CleanRL do. Same loop defaults as TD3 (learning_rate 1e-3,
// batch_size 256, ...).
#pragma once

#include <memory>

#include "learn/learner.h"

namespace cradle::learn {

// A DDPG learner on `env` (which must outlive it). Throws UserError for bad options, an action
// space without finite bounds, or a replay buffer too large for the machine.
std::unique_ptr<Learner> make_ddpg(VecEnv& env, const LearnerOptions& options);

}  // namespace cradle::learn

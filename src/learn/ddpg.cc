// DDPG, top to bottom (one update; OffPolicyLearner runs the replay loop around it):
//   sample a minibatch (s, a, r, s', terminated) from the replay buffer
//   y = r + gamma (1 - terminated) Q'(s', mu'(s'))
//   J(Q) = mean((Q(s, a) - y)^2)            one Adam step on the critic
//   J(mu) = -mean(Q(s, mu(s)))              one Adam step on the actor
//   Q' <- tau Q + (1 - tau) Q',  mu' <- tau mu + (1 - tau) mu'
// It is TD3's update (td3.cc) with one critic, no delay and no target smoothing.
#include "learn/ddpg.h"

#include "learn/td3.h"

namespace cradle::learn {

std::unique_ptr<Learner> make_ddpg(VecEnv& env, const LearnerOptions& options) {
  return make_td3_variant("ddpg", env, options,
                          {.policy_delay = 1,           // SB3 DDPG: policy_delay=1
                           .target_policy_noise = 0.0,  // SB3 DDPG: target_policy_noise=0
                           .target_noise_clip = 0.0,    // SB3 DDPG: target_noise_clip=0
                           .exploration_noise = 0.1,    // N(0, 0.1), as TD3
                           .n_critics = 1,              // SB3 DDPG: n_critics=1
                           .ddpg = true});
}

}  // namespace cradle::learn

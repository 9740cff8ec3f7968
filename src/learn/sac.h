// Soft Actor-Critic (Haarnoja et al. 2018, "Soft Actor-Critic Algorithms and Applications"):
// a tanh-squashed Gaussian policy maximising return plus entropy, twin Q critics with Polyak
// target copies, and the temperature alpha tuned automatically towards a target entropy, as in
// Stable-Baselines3's SAC. Defaults are SB3's; the comment after each field gives SB3's name
// where it differs or needs saying.
#pragma once

#include <torch/torch.h>

#include <memory>
#include <string>
#include <utility>

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

// The SAC update's formulas on given tensors, shared with the context learners of learn/meta/.
// a = tanh(mean + exp(log_std) eps), eps ~ N(0, I), log_std clamped to [-20, 2], with log pi(a|s)
// by the change of variables: {a [B, A], log_pi [B]}.
std::pair<torch::Tensor, torch::Tensor> squashed_gaussian_sample(const torch::Tensor& mean,
                                                                 const torch::Tensor& log_std,
                                                                 at::Generator& generator);
// J(alpha) = mean(-log alpha (log pi + target_entropy)).
torch::Tensor sac_alpha_loss(const torch::Tensor& log_alpha, const torch::Tensor& log_pi,
                             double target_entropy);
// y = r + gamma (1 - terminated) (min_i Q'_i - alpha log pi'), from next_q [critics, B].
torch::Tensor sac_soft_target(const torch::Tensor& rewards, const torch::Tensor& terminated,
                              const torch::Tensor& next_q, const torch::Tensor& next_log_pi,
                              const torch::Tensor& alpha, double gamma);
// Each critic's mean squared error to the target: [critics] (J(Q) is half their sum).
torch::Tensor sac_critic_losses(const torch::Tensor& q, const torch::Tensor& target);
// J(pi) = mean(alpha log pi - min_i Q_i), from q_pi [critics, B].
torch::Tensor sac_actor_loss(const torch::Tensor& alpha, const torch::Tensor& log_pi,
                             const torch::Tensor& q_pi);

}  // namespace cradle::learn

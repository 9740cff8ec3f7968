// A2C, top to bottom (the loop around the update is on_policy.h's):
//   for each iteration until the step budget is spent:
//     (optionally) anneal the learning rate
//     collect n_steps x num_envs transitions with the current Gaussian policy
//     compute advantages A and value targets R by GAE(gamma, lambda = 1: n-step returns)
//     the update, in this file:
//       L_policy = -mean(A log pi(a|s))
//       L_value = mean((R - V(s))^2)
//       L = L_policy - ent_coef * entropy + vf_coef * L_value
//       one RMSprop step on L with the gradient norm clipped to max_grad_norm
//   reporting the updates' mean losses about every 2,048 steps per env
// With overlap_update=true rollout k+1 is collected during the update of rollout k, with the
// policy from before it (on_policy.h); A2C's loss has no importance ratio, so its gradient is
// then that of a policy one update old, uncorrected.
#include "learn/a2c.h"

#include <torch/torch.h>

#include <algorithm>

#include "core/error.h"
#include "learn/on_policy.h"

namespace cradle::learn {

void A2cConfig::bind(Hyperparameters& table) {
  table.add("learning_rate", &learning_rate, "RMSprop step size");
  table.add("anneal_lr", &anneal_lr, "decay the learning rate linearly to 0 over the run");
  table.add("n_steps", &n_steps, "steps per env per rollout");
  table.add("gamma", &gamma, "discount factor");
  table.add("gae_lambda", &gae_lambda, "GAE lambda (1: n-step returns)");
  table.add("ent_coef", &ent_coef, "entropy bonus weight");
  table.add("vf_coef", &vf_coef, "value loss weight");
  table.add("max_grad_norm", &max_grad_norm, "gradient norm clip");
  table.add("rms_prop_alpha", &rms_prop_alpha, "RMSprop smoothing constant");
  table.add("rms_prop_eps", &rms_prop_eps, "RMSprop epsilon");
  table.add("normalize_advantage", &normalize_advantage, "standardise advantages per rollout");
  table.add("overlap_update", &overlap_update,
            "collect the next rollout while updating on this one (one update of policy lag)");
}

namespace {

using A2cSettings = OnPolicySettings<A2cConfig>;

A2cSettings parse_settings(const LearnerOptions& options) {
  A2cSettings settings = parse_on_policy_settings<A2cConfig>(options);
  if (settings.own.n_steps < 1) throw UserError("a2c: n_steps must be positive");
  // Short rollouts: report about every 2,048 steps per env.
  settings.loop.report_every = std::max(1, 2048 / settings.own.n_steps);
  return settings;
}

class A2c final : public OnPolicyLearner {
 public:
  A2c(VecEnv& env, const LearnerOptions& options) : A2c(env, options, parse_settings(options)) {}

 private:
  A2c(VecEnv& env, const LearnerOptions& options, A2cSettings settings)
      : OnPolicyLearner("a2c", env, options, settings),
        config_(settings.own),
        optimizer_(std::vector<torch::Tensor>{parameters().tensor()},
                   torch::optim::RMSpropOptions(config_.learning_rate)
                       .alpha(config_.rms_prop_alpha)
                       .eps(config_.rms_prop_eps)
                       .weight_decay(0)) {
    use_optimizer(optimizer_);
  }

  // One gradient step on the whole rollout.
  std::map<std::string, double> update() override {
    const torch::Tensor rows = buffer().valid_rows();
    // Data-parallel: a rank without a transition still joins the all-reduce, with a zero gradient.
    if (agree_max(sync(), static_cast<double>(rows.size(0))) == 0) return {};
    if (rows.size(0) == 0) {
      gradient_step(torch::Tensor(), config_.max_grad_norm);
      return {};
    }
    const Batch b = evaluate(rows, config_.normalize_advantage);

    // Policy gradient with the advantage as the baseline-corrected return.
    const torch::Tensor policy_loss = -(b.advantages * b.log_probs).mean();
    const torch::Tensor value_loss = (b.returns - b.out.value).square().mean();
    const Loss loss = actor_critic_loss(policy_loss, value_loss, config_.ent_coef, config_.vf_coef);

    gradient_step(loss.total, config_.max_grad_norm);

    return {{"policy_loss", policy_loss.item<double>()},
            {"value_loss", value_loss.item<double>()},
            {"entropy", loss.entropy.item<double>()},
            {"loss", loss.total.item<double>()},
            {"std", policy_std()}};
  }

  const A2cConfig config_;
  torch::optim::RMSprop optimizer_;
};

}  // namespace

std::unique_ptr<Learner> make_a2c(VecEnv& env, const LearnerOptions& options) {
  return std::make_unique<A2c>(env, options);
}

}  // namespace cradle::learn

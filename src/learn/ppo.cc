// PPO, top to bottom (the loop around the update is on_policy.h's):
//   for each iteration until the step budget is spent:
//     (optionally) anneal the learning rate
//     collect n_steps x num_envs transitions with the current Gaussian policy
//     compute advantages A and value targets R by GAE(gamma, lambda)
//     the update, in this file: for n_epochs: for each shuffled minibatch:
//       ratio r = pi(a|s) / pi_old(a|s)
//       L_clip = -mean(min(r A, clip(r, 1 - eps, 1 + eps) A))
//       L_value = mean((R - V(s))^2)            (V optionally clipped around V_old)
//       L = L_clip - ent_coef * entropy + vf_coef * L_value
//       one Adam step on L with the gradient norm clipped to max_grad_norm
// With overlap_update=true the collection of rollout k+1 runs on its own thread during the update
// of rollout k, acting with the policy from before that update (one update of lag; pi_old in r is
// the policy that collected, whose log-probabilities the buffer holds). See on_policy.h.
#include "learn/ppo.h"

#include <torch/torch.h>

#include <cmath>
#include <limits>

#include "core/error.h"
#include "learn/on_policy.h"

namespace cradle::learn {

void PpoConfig::bind(Hyperparameters& table) {
  table.add("learning_rate", &learning_rate, "Adam step size");
  table.add("anneal_lr", &anneal_lr, "decay the learning rate linearly to 0 over the run");
  table.add("n_steps", &n_steps, "steps per env per rollout");
  table.add("batch_size", &batch_size, "minibatch size");
  table.add("n_epochs", &n_epochs, "optimisation passes over each rollout");
  table.add("gamma", &gamma, "discount factor");
  table.add("gae_lambda", &gae_lambda, "GAE lambda");
  table.add("clip_range", &clip_range, "policy ratio clip epsilon");
  table.add("clip_range_vf", &clip_range_vf, "value clip around the old value (<= 0: off)");
  table.add("normalize_advantage", &normalize_advantage, "standardise advantages per minibatch");
  table.add("ent_coef", &ent_coef, "entropy bonus weight");
  table.add("vf_coef", &vf_coef, "value loss weight");
  table.add("max_grad_norm", &max_grad_norm, "gradient norm clip");
  table.add("target_kl", &target_kl, "early stop at approx KL > 1.5 x this (<= 0: off)");
  table.add("adam_eps", &adam_eps, "Adam epsilon");
  table.add("normalize_returns", &normalize_returns,
            "divide rewards by the running std of the discounted return, clip +-10");
  table.add("overlap_update", &overlap_update,
            "collect the next rollout while updating on this one (one update of policy lag)");
}

namespace {

using PpoSettings = OnPolicySettings<PpoConfig>;

PpoSettings parse_settings(const LearnerOptions& options) {
  PpoSettings settings = parse_on_policy_settings<PpoConfig>(options);
  const PpoConfig& c = settings.own;
  if (c.n_steps < 1 || c.batch_size < 1 || c.n_epochs < 1) {
    throw UserError("ppo: n_steps, batch_size and n_epochs must be positive");
  }
  if (c.normalize_advantage && c.batch_size < 2) {
    throw UserError("ppo: normalize_advantage needs batch_size > 1");
  }
  settings.loop.normalize_returns = c.normalize_returns;
  return settings;
}

class Ppo final : public OnPolicyLearner {
 public:
  Ppo(VecEnv& env, const LearnerOptions& options) : Ppo(env, options, parse_settings(options)) {}

 private:
  Ppo(VecEnv& env, const LearnerOptions& options, PpoSettings settings)
      : OnPolicyLearner("ppo", env, options, settings),
        config_(settings.own),
        optimizer_(std::vector<torch::Tensor>{parameters().tensor()},
                   torch::optim::AdamOptions(config_.learning_rate).eps(config_.adam_eps)) {
    use_optimizer(optimizer_);
    // A minibatch cannot be larger than the rollout it is drawn from.
    const long rollout = static_cast<long>(config_.n_steps) * env.num_envs();
    if (config_.batch_size > rollout) {
      throw UserError("ppo: batch_size " + std::to_string(config_.batch_size) +
                      " is larger than the rollout (n_steps x envs = " + std::to_string(rollout) +
                      ")");
    }
  }

  // n_epochs passes of minibatch gradient steps over the rollout's valid rows.
  std::map<std::string, double> update() override {
    const torch::Tensor rows = buffer().valid_rows();
    const long n = rows.size(0);
    // Data-parallel: every rank takes as many minibatches as the rank with the most valid rows
    // (the others wrap around their shuffled rows), so the gradient all-reduces pair up.
    const long rows_per_epoch = static_cast<long>(agree_max(sync(), static_cast<double>(n)));
    if (rows_per_epoch == 0) return {};
    if (n == 0) throw UserError("ppo: a rank's rollout holds no transition: raise n_steps");
    double policy_loss_sum = 0, value_loss_sum = 0, kl_sum = 0, clip_sum = 0, loss = 0;
    long minibatches = 0;
    bool keep_going = true;
    for (int epoch = 0; epoch < config_.n_epochs && keep_going; ++epoch) {
      torch::Tensor order = rows.index_select(0, torch::randperm(n, generator()));
      if (rows_per_epoch > n) order = order.repeat({(rows_per_epoch + n - 1) / n});
      for (long begin = 0; begin < rows_per_epoch; begin += config_.batch_size) {
        const torch::Tensor index =
            order.slice(0, begin, std::min(rows_per_epoch, begin + config_.batch_size));
        const Batch b = evaluate(index, config_.normalize_advantage);
        const torch::Tensor& advantages = b.advantages;

        // Clipped surrogate: -mean(min(r A, clip(r, 1 - eps, 1 + eps) A)).
        const torch::Tensor log_ratio = b.log_probs - b.old_log_probs;
        const torch::Tensor ratio = torch::exp(log_ratio);
        const torch::Tensor clipped =
            torch::clamp(ratio, 1.0 - config_.clip_range, 1.0 + config_.clip_range);
        const torch::Tensor policy_loss =
            -torch::min(ratio * advantages, clipped * advantages).mean();

        // Value loss against the GAE returns, the prediction optionally kept near the old value.
        torch::Tensor values = b.out.value;
        if (config_.clip_range_vf > 0) {
          values = b.old_values + torch::clamp(values - b.old_values, -config_.clip_range_vf,
                                               config_.clip_range_vf);
        }
        const torch::Tensor value_loss = (b.returns - values).square().mean();
        const torch::Tensor total =
            actor_critic_loss(policy_loss, value_loss, config_.ent_coef, config_.vf_coef).total;

        // Approximate KL(old || new) = E[(r - 1) - log r] (Schulman's low-variance estimator).
        // Data-parallel: the ranks' mean, so that every rank stops at the same minibatch.
        const double approx_kl =
            config_.target_kl > 0
                ? agree_mean(sync(), ((ratio - 1) - log_ratio).mean().item<double>())
                : ((ratio - 1) - log_ratio).mean().item<double>();
        if (config_.target_kl > 0 && approx_kl > 1.5 * config_.target_kl) {
          keep_going = false;
          break;
        }

        gradient_step(total, config_.max_grad_norm);

        policy_loss_sum += policy_loss.item<double>();
        value_loss_sum += value_loss.item<double>();
        kl_sum += approx_kl;
        clip_sum +=
            (torch::abs(ratio - 1) > config_.clip_range).to(torch::kFloat32).mean().item<double>();
        loss = total.item<double>();
        ++minibatches;
      }
    }
    const double m = std::max<long>(minibatches, 1);
    return {{"policy_loss", policy_loss_sum / m},
            {"value_loss", value_loss_sum / m},
            {"approx_kl", kl_sum / m},
            {"clip_fraction", clip_sum / m},
            {"loss", loss},
            {"entropy", policy()->entropy().item<double>()},
            {"std", policy_std()},
            {"explained_variance", explained_variance(rows)},
            {"minibatches", static_cast<double>(minibatches)}};
  }

  // 1 - Var(R - V) / Var(R) over the valid rows: how much of the return the value predicts.
  double explained_variance(const torch::Tensor& rows) {
    const torch::Tensor returns = buffer().returns.index_select(0, rows);
    const torch::Tensor values = buffer().values.index_select(0, rows);
    const double var = returns.var(/*unbiased=*/false).item<double>();
    if (var == 0) return std::numeric_limits<double>::quiet_NaN();
    return 1.0 - (returns - values).var(/*unbiased=*/false).item<double>() / var;
  }

  const PpoConfig config_;
  torch::optim::Adam optimizer_;
};

}  // namespace

std::unique_ptr<Learner> make_ppo(VecEnv& env, const LearnerOptions& options) {
  return std::make_unique<Ppo>(env, options);
}

}  // namespace cradle::learn

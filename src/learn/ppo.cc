// PPO, top to bottom:
//   for each iteration until the step budget is spent:
//     (optionally) anneal the learning rate
//     collect n_steps x num_envs transitions with the current Gaussian policy
//     compute advantages A and value targets R by GAE(gamma, lambda)
//     for n_epochs: for each shuffled minibatch:
//       ratio r = pi(a|s) / pi_old(a|s)
//       L_clip = -mean(min(r A, clip(r, 1 - eps, 1 + eps) A))
//       L_value = mean((R - V(s))^2)            (V optionally clipped around V_old)
//       L = L_clip - ent_coef * entropy + vf_coef * L_value
//       one Adam step on L with the gradient norm clipped to max_grad_norm
#include "learn/ppo.h"

#include <torch/torch.h>

#include <chrono>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "learn/checkpoint.h"
#include "learn/grad_sync.h"
#include "learn/networks.h"
#include "learn/preprocess.h"
#include "learn/rollout.h"

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
}

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

struct PpoSettings {
  PpoConfig ppo;
  ObservationConfig observation;
  PolicyConfig policy;
  std::string text;  // every value, "name = value" lines
};

PpoSettings parse_settings(const LearnerOptions& options) {
  apply_torch_options(options);
  PpoSettings settings;
  Hyperparameters table;
  settings.ppo.bind(table);
  settings.observation.bind(table);
  settings.policy.bind(table);
  table.apply(options.hyperparameters);
  const PpoConfig& c = settings.ppo;
  if (c.n_steps < 1 || c.batch_size < 1 || c.n_epochs < 1) {
    throw UserError("ppo: n_steps, batch_size and n_epochs must be positive");
  }
  if (c.normalize_advantage && c.batch_size < 2) {
    throw UserError("ppo: normalize_advantage needs batch_size > 1");
  }
  settings.text = table.to_text();
  return settings;
}

class Ppo final : public Learner {
 public:
  Ppo(VecEnv& env, const LearnerOptions& options)
      : settings_(parse_settings(options)),
        config_(settings_.ppo),
        env_(env),
        generator_(at::make_generator<at::CPUGeneratorImpl>(options.seed)),
        pipeline_(env.observation_space(), settings_.observation, find_touch(env)),
        policy_(pipeline_.shape(), env.action_space().size(), settings_.policy, generator_),
        parameters_(*policy_),
        optimizer_(std::vector<torch::Tensor>{parameters_.tensor()},
                   torch::optim::AdamOptions(config_.learning_rate).eps(config_.adam_eps)),
        buffer_(config_.n_steps, env.num_envs(), pipeline_.shape(), env.action_space().size()),
        collector_(env, pipeline_, options.reward_hook),
        scratch_(ObsBatch::zeros(pipeline_.shape(), 1)),
        update_threads_(update_threads(options, pipeline_.shape())),
        sync_(options.sync) {
    // Data-parallel: every rank starts from rank 0's parameters.
    broadcast_tensor(sync_.get(), parameters_.tensor());
    // A minibatch cannot be larger than the rollout it is drawn from.
    const long rollout = static_cast<long>(config_.n_steps) * env.num_envs();
    if (config_.batch_size > rollout) {
      throw UserError("ppo: batch_size " + std::to_string(config_.batch_size) +
                      " is larger than the rollout (n_steps x envs = " + std::to_string(rollout) +
                      ")");
    }
  }

  std::string_view algorithm() const override { return "ppo"; }
  long steps() const override { return steps_; }
  std::string config_text() const override { return settings_.text; }

  void learn(long total_steps, const ProgressFn& on_progress) override {
    const Clock::time_point start = Clock::now();
    const long start_steps = steps_;
    collector_.start(draw_env_seed(generator_));
    while (steps_ < total_steps) {
      // Learning rate for this iteration: constant, or annealed linearly to 0.
      double learning_rate = config_.learning_rate;
      if (config_.anneal_lr) {
        learning_rate *= 1.0 - static_cast<double>(steps_) / static_cast<double>(total_steps);
      }
      for (auto& group : optimizer_.param_groups()) group.options().set_lr(learning_rate);

      // Collect a rollout with the current policy, then GAE advantages and value targets.
      const Clock::time_point collect_start = Clock::now();
      collector_.collect(policy_, generator_, buffer_);
      steps_ += static_cast<long>(buffer_.rows()) * world_size(sync_.get());  // every rank's
      pipeline_.merge_statistics(sync_.get());
      buffer_.compute_returns_and_advantages(config_.gamma, config_.gae_lambda);

      // Optimise the clipped surrogate on it.
      const Clock::time_point update_start = Clock::now();
      TrainStats stats{.steps = steps_};
      {
        const ScopedTorchThreads threads(update_threads_);
        stats.losses = update();
      }
      stats.losses["learning_rate"] = learning_rate;
      stats.losses["collect_seconds"] = seconds_since(collect_start) - seconds_since(update_start);
      stats.losses["update_seconds"] = seconds_since(update_start);

      const EpisodeStats::Summary episodes = collector_.episodes().take();
      stats.episodes = episodes.episodes;
      stats.episodic_return = episodes.mean_return;
      stats.episodic_length = episodes.mean_length;
      stats.sps = static_cast<double>(steps_ - start_steps) / std::max(seconds_since(start), 1e-9);
      if (on_progress && !on_progress(stats)) break;
    }
  }

  void save(const std::filesystem::path& file) const override {
    save_policy_checkpoint(file, {.algorithm = "ppo", .config = settings_.text, .steps = steps_},
                           *policy_, optimizer_, pipeline_, generator_);
  }

  void load(const std::filesystem::path& file) override {
    steps_ = load_policy_checkpoint(file, "ppo", settings_.observation, *policy_, optimizer_,
                                    pipeline_, generator_)
                 .steps;
    offset_generator(sync_.get(), generator_);
  }

  std::uint64_t parameter_hash() const override { return tensor_hash({parameters_.tensor()}); }

  void act(const envs::ObservationBuffers& observation, std::span<double> action,
           bool deterministic) override {
    act_gaussian(pipeline_, policy_, generator_, env_.action_space(), observation, scratch_, action,
                 deterministic);
  }

  double value(const envs::ObservationBuffers& observation) override {
    return state_value(pipeline_, policy_, observation, scratch_);
  }

 private:
  // n_epochs passes of minibatch gradient steps over the rollout's valid rows.
  std::map<std::string, double> update() {
    const torch::Tensor rows = buffer_.valid_rows();
    const long n = rows.size(0);
    // Data-parallel: every rank takes as many minibatches as the rank with the most valid rows
    // (the others wrap around their shuffled rows), so the gradient all-reduces pair up.
    const long rows_per_epoch = static_cast<long>(agree_max(sync_.get(), static_cast<double>(n)));
    if (rows_per_epoch == 0) return {};
    if (n == 0) throw UserError("ppo: a rank's rollout holds no transition: raise n_steps");
    double policy_loss_sum = 0, value_loss_sum = 0, kl_sum = 0, clip_sum = 0, loss = 0;
    long minibatches = 0;
    bool keep_going = true;
    for (int epoch = 0; epoch < config_.n_epochs && keep_going; ++epoch) {
      torch::Tensor order = rows.index_select(0, torch::randperm(n, generator_));
      if (rows_per_epoch > n) order = order.repeat({(rows_per_epoch + n - 1) / n});
      for (long begin = 0; begin < rows_per_epoch; begin += config_.batch_size) {
        const torch::Tensor index =
            order.slice(0, begin, std::min(rows_per_epoch, begin + config_.batch_size));
        const ObsBatch observations = buffer_.observations.select(index);
        const torch::Tensor actions = buffer_.actions.index_select(0, index);
        const torch::Tensor old_log_probs = buffer_.log_probs.index_select(0, index);
        const torch::Tensor old_values = buffer_.values.index_select(0, index);
        const torch::Tensor returns = buffer_.returns.index_select(0, index);
        torch::Tensor advantages = buffer_.advantages.index_select(0, index);
        if (config_.normalize_advantage && index.size(0) > 1) {
          advantages = (advantages - advantages.mean()) / (advantages.std() + 1e-8);
        }

        const GaussianActorCriticImpl::Output out = policy_->forward(observations);
        const torch::Tensor log_probs = policy_->log_prob(out.mean, actions);

        // Clipped surrogate: -mean(min(r A, clip(r, 1 - eps, 1 + eps) A)).
        const torch::Tensor log_ratio = log_probs - old_log_probs;
        const torch::Tensor ratio = torch::exp(log_ratio);
        const torch::Tensor clipped =
            torch::clamp(ratio, 1.0 - config_.clip_range, 1.0 + config_.clip_range);
        const torch::Tensor policy_loss =
            -torch::min(ratio * advantages, clipped * advantages).mean();

        // Value loss against the GAE returns, the prediction optionally kept near the old value.
        torch::Tensor values = out.value;
        if (config_.clip_range_vf > 0) {
          values = old_values +
                   torch::clamp(values - old_values, -config_.clip_range_vf, config_.clip_range_vf);
        }
        const torch::Tensor value_loss = (returns - values).square().mean();

        const torch::Tensor entropy = policy_->entropy();
        const torch::Tensor total =
            policy_loss - config_.ent_coef * entropy + config_.vf_coef * value_loss;

        // Approximate KL(old || new) = E[(r - 1) - log r] (Schulman's low-variance estimator).
        // Data-parallel: the ranks' mean, so that every rank stops at the same minibatch.
        const double approx_kl =
            config_.target_kl > 0
                ? agree_mean(sync_.get(), ((ratio - 1) - log_ratio).mean().item<double>())
                : ((ratio - 1) - log_ratio).mean().item<double>();
        if (config_.target_kl > 0 && approx_kl > 1.5 * config_.target_kl) {
          keep_going = false;
          break;
        }

        parameters_.zero_grad();
        total.backward();
        average_gradients(sync_.get(), parameters_.tensor().grad());
        torch::nn::utils::clip_grad_norm_(parameters_.tensor(), config_.max_grad_norm);
        optimizer_.step();

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
            {"entropy", policy_->entropy().item<double>()},
            {"std", torch::exp(policy_->log_std()).mean().item<double>()},
            {"explained_variance", explained_variance(rows)},
            {"minibatches", static_cast<double>(minibatches)}};
  }

  // 1 - Var(R - V) / Var(R) over the valid rows: how much of the return the value predicts.
  double explained_variance(const torch::Tensor& rows) const {
    const torch::Tensor returns = buffer_.returns.index_select(0, rows);
    const torch::Tensor values = buffer_.values.index_select(0, rows);
    const double var = returns.var(/*unbiased=*/false).item<double>();
    if (var == 0) return std::numeric_limits<double>::quiet_NaN();
    return 1.0 - (returns - values).var(/*unbiased=*/false).item<double>() / var;
  }

  const PpoSettings settings_;
  const PpoConfig& config_;
  VecEnv& env_;
  at::Generator generator_;
  ObservationPipeline pipeline_;
  GaussianActorCritic policy_;
  PackedParameters parameters_;  // policy_'s parameters, packed for the optimiser
  torch::optim::Adam optimizer_;
  RolloutBuffer buffer_;
  RolloutCollector collector_;
  ObsBatch scratch_;  // one row, for act()
  const int update_threads_;
  const std::shared_ptr<GradSync> sync_;  // null: alone
  long steps_ = 0;
};

}  // namespace

std::unique_ptr<Learner> make_ppo(VecEnv& env, const LearnerOptions& options) {
  return std::make_unique<Ppo>(env, options);
}

}  // namespace cradle::learn

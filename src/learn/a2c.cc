// A2C, top to bottom:
//   for each iteration until the step budget is spent:
//     (optionally) anneal the learning rate
//     collect n_steps x num_envs transitions with the current Gaussian policy
//     compute advantages A and value targets R by GAE(gamma, lambda = 1: n-step returns)
//     L_policy = -mean(A log pi(a|s))
//     L_value = mean((R - V(s))^2)
//     L = L_policy - ent_coef * entropy + vf_coef * L_value
//     one RMSprop step on L with the gradient norm clipped to max_grad_norm
#include "learn/a2c.h"

#include <torch/torch.h>

#include <chrono>
#include <utility>

#include "core/error.h"
#include "learn/checkpoint.h"
#include "learn/grad_sync.h"
#include "learn/networks.h"
#include "learn/preprocess.h"
#include "learn/rollout.h"

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
}

namespace {

using Clock = std::chrono::steady_clock;

struct A2cSettings {
  A2cConfig a2c;
  ObservationConfig observation;
  PolicyConfig policy;
  std::string text;  // every value, "name = value" lines
};

A2cSettings parse_settings(const LearnerOptions& options) {
  apply_torch_options(options);
  A2cSettings settings;
  Hyperparameters table;
  settings.a2c.bind(table);
  settings.observation.bind(table);
  settings.policy.bind(table);
  table.apply(options.hyperparameters);
  if (settings.a2c.n_steps < 1) throw UserError("a2c: n_steps must be positive");
  settings.text = table.to_text();
  return settings;
}

class A2c final : public Learner {
 public:
  A2c(VecEnv& env, const LearnerOptions& options)
      : settings_(parse_settings(options)),
        config_(settings_.a2c),
        env_(env),
        generator_(at::make_generator<at::CPUGeneratorImpl>(options.seed)),
        pipeline_(env.observation_space(), settings_.observation, find_touch(env)),
        policy_(pipeline_.shape(), env.action_space().size(), settings_.policy, generator_),
        parameters_(*policy_),
        optimizer_(std::vector<torch::Tensor>{parameters_.tensor()},
                   torch::optim::RMSpropOptions(config_.learning_rate)
                       .alpha(config_.rms_prop_alpha)
                       .eps(config_.rms_prop_eps)
                       .weight_decay(0)),
        buffer_(config_.n_steps, env.num_envs(), pipeline_.shape(), env.action_space().size()),
        collector_(env, pipeline_, options.reward_hook),
        scratch_(ObsBatch::zeros(pipeline_.shape(), 1)),
        sync_(options.sync) {
    // Data-parallel: every rank starts from rank 0's parameters.
    broadcast_tensor(sync_.get(), parameters_.tensor());
  }

  std::string_view algorithm() const override { return "a2c"; }
  long steps() const override { return steps_; }
  std::string config_text() const override { return settings_.text; }

  void learn(long total_steps, const ProgressFn& on_progress) override {
    const Clock::time_point start = Clock::now();
    const long start_steps = steps_;
    collector_.start(draw_env_seed(generator_));
    // A2C's rollouts are short: report about every 2,048 steps per env, not every update.
    const long report_every = std::max<long>(1, 2048 / config_.n_steps);
    long iteration = 0;
    std::map<std::string, double> sums;
    double collect_seconds = 0, update_seconds = 0;  // since the last report
    while (steps_ < total_steps) {
      // Learning rate for this iteration: constant, or annealed linearly to 0.
      double learning_rate = config_.learning_rate;
      if (config_.anneal_lr) {
        learning_rate *= 1.0 - static_cast<double>(steps_) / static_cast<double>(total_steps);
      }
      for (auto& group : optimizer_.param_groups()) group.options().set_lr(learning_rate);

      // Collect a rollout with the current policy, then n-step advantages and value targets.
      const Clock::time_point collect_start = Clock::now();
      collector_.collect(policy_, generator_, buffer_);
      steps_ += static_cast<long>(buffer_.rows()) * world_size(sync_.get());  // every rank's
      pipeline_.merge_statistics(sync_.get());
      buffer_.compute_returns_and_advantages(config_.gamma, config_.gae_lambda);

      // One gradient step on the whole rollout.
      const Clock::time_point update_start = Clock::now();
      for (const auto& [name, value] : update()) sums[name] += value;
      collect_seconds += std::chrono::duration<double>(update_start - collect_start).count();
      update_seconds += std::chrono::duration<double>(Clock::now() - update_start).count();
      ++iteration;

      if (iteration % report_every != 0 && steps_ < total_steps) continue;
      TrainStats stats{.steps = steps_};
      const double updates = static_cast<double>((iteration - 1) % report_every + 1);
      for (const auto& [name, value] : sums) stats.losses[name] = value / updates;
      sums.clear();
      stats.losses["learning_rate"] = learning_rate;
      stats.losses["collect_seconds"] = std::exchange(collect_seconds, 0.0);
      stats.losses["update_seconds"] = std::exchange(update_seconds, 0.0);
      const EpisodeStats::Summary episodes = collector_.episodes().take();
      stats.episodes = episodes.episodes;
      stats.episodic_return = episodes.mean_return;
      stats.episodic_length = episodes.mean_length;
      const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
      stats.sps = static_cast<double>(steps_ - start_steps) / std::max(seconds, 1e-9);
      if (on_progress && !on_progress(stats)) break;
    }
  }

  void save(const std::filesystem::path& file) const override {
    save_policy_checkpoint(file, {.algorithm = "a2c", .config = settings_.text, .steps = steps_},
                           *policy_, optimizer_, pipeline_, generator_);
  }

  void load(const std::filesystem::path& file) override {
    steps_ = load_policy_checkpoint(file, "a2c", settings_.observation, *policy_, optimizer_,
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

 private:
  std::map<std::string, double> update() {
    const torch::Tensor rows = buffer_.valid_rows();
    // Data-parallel: a rank without a transition still joins the all-reduce, with a zero gradient.
    if (agree_max(sync_.get(), static_cast<double>(rows.size(0))) == 0) return {};
    if (rows.size(0) == 0) {
      parameters_.zero_grad();
      average_gradients(sync_.get(), parameters_.tensor().grad());
      torch::nn::utils::clip_grad_norm_(parameters_.tensor(), config_.max_grad_norm);
      optimizer_.step();
      return {};
    }
    const ObsBatch observations = buffer_.observations.select(rows);
    const torch::Tensor actions = buffer_.actions.index_select(0, rows);
    const torch::Tensor returns = buffer_.returns.index_select(0, rows);
    torch::Tensor advantages = buffer_.advantages.index_select(0, rows);
    if (config_.normalize_advantage && rows.size(0) > 1) {
      advantages = (advantages - advantages.mean()) / (advantages.std() + 1e-8);
    }

    const GaussianActorCriticImpl::Output out = policy_->forward(observations);
    const torch::Tensor log_probs = policy_->log_prob(out.mean, actions);

    // Policy gradient with the advantage as the baseline-corrected return.
    const torch::Tensor policy_loss = -(advantages * log_probs).mean();
    const torch::Tensor value_loss = (returns - out.value).square().mean();
    const torch::Tensor entropy = policy_->entropy();
    const torch::Tensor total =
        policy_loss - config_.ent_coef * entropy + config_.vf_coef * value_loss;

    parameters_.zero_grad();
    total.backward();
    average_gradients(sync_.get(), parameters_.tensor().grad());
    torch::nn::utils::clip_grad_norm_(parameters_.tensor(), config_.max_grad_norm);
    optimizer_.step();

    return {{"policy_loss", policy_loss.item<double>()},
            {"value_loss", value_loss.item<double>()},
            {"entropy", entropy.item<double>()},
            {"loss", total.item<double>()},
            {"std", torch::exp(policy_->log_std()).mean().item<double>()}};
  }

  const A2cSettings settings_;
  const A2cConfig& config_;
  VecEnv& env_;
  at::Generator generator_;
  ObservationPipeline pipeline_;
  GaussianActorCritic policy_;
  PackedParameters parameters_;  // policy_'s parameters, packed for the optimiser
  torch::optim::RMSprop optimizer_;
  RolloutBuffer buffer_;
  RolloutCollector collector_;
  ObsBatch scratch_;                      // one row, for act()
  const std::shared_ptr<GradSync> sync_;  // null: alone
  long steps_ = 0;
};

}  // namespace

std::unique_ptr<Learner> make_a2c(VecEnv& env, const LearnerOptions& options) {
  return std::make_unique<A2c>(env, options);
}

}  // namespace cradle::learn

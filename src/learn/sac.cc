// SAC, top to bottom (one update; OffPolicyLearner runs the replay loop around it):
//   sample a minibatch (s, a, r, s', terminated) from the replay buffer
//   a~ ~ pi(.|s), with log pi(a~|s)                  (tanh-squashed Gaussian, reparameterised)
//   J(alpha) = mean(-log alpha (log pi(a~|s) + target_entropy))   one Adam step on log alpha
//   y = r + gamma (1 - terminated) (min_i Q'_i(s', a') - alpha log pi(a'|s')),  a' ~ pi(.|s')
//   J(Q) = 1/2 sum_i mean((Q_i(s, a) - y)^2)                       one Adam step on the critics
//   J(pi) = mean(alpha log pi(a~|s) - min_i Q_i(s, a~))            one Adam step on the actor
//   every target_update_interval updates: Q' <- tau Q + (1 - tau) Q'
// alpha in the targets and the actor loss is the value before this update's temperature step.
#include "learn/sac.h"

#include <torch/torch.h>

#include <charconv>
#include <cmath>
#include <numbers>

#include "core/error.h"

namespace cradle::learn {

void SacConfig::bind(Hyperparameters& table) {
  table.add("ent_coef", &ent_coef, "temperature: auto, auto_<init> or a fixed number");
  table.add("target_entropy", &target_entropy, "entropy target: auto (-action dim) or a number");
  table.add("target_update_interval", &target_update_interval, "updates between target updates");
  table.add("n_critics", &n_critics, "Q networks (targets take their minimum)");
}

OffPolicyConfig sac_loop_defaults() {
  return {.learning_rate = 3e-4,     // SB3 SAC learning_rate
          .buffer_size = 1'000'000,  // SB3 buffer_size
          .learning_starts = 100,    // SB3 learning_starts
          .batch_size = 256,         // SB3 batch_size
          .tau = 0.005,              // SB3 tau
          .gamma = 0.99,             // SB3 gamma
          .train_freq = 1,           // SB3 train_freq (1, "step")
          .gradient_steps = 1};      // SB3 gradient_steps
}

namespace {

// log_std bounds of the policy head (SB3's LOG_STD_MIN, LOG_STD_MAX).
constexpr double kLogStdMin = -20.0;
constexpr double kLogStdMax = 2.0;

}  // namespace

std::pair<torch::Tensor, torch::Tensor> squashed_gaussian_sample(const torch::Tensor& mean,
                                                                 const torch::Tensor& log_std_raw,
                                                                 at::Generator& generator) {
  const torch::Tensor log_std = torch::clamp(log_std_raw, kLogStdMin, kLogStdMax);
  const torch::Tensor eps = torch::randn(mean.sizes(), generator, torch::kFloat32);
  const torch::Tensor u = mean + torch::exp(log_std) * eps;
  const double half_log_2pi = 0.5 * std::log(2.0 * std::numbers::pi);
  const torch::Tensor log_gaussian = -0.5 * eps.square() - log_std - half_log_2pi;
  const torch::Tensor log_jacobian =
      2.0 * (std::numbers::ln2 - u - torch::nn::functional::softplus(-2.0 * u));
  return {torch::tanh(u), (log_gaussian - log_jacobian).sum(1)};
}

torch::Tensor sac_alpha_loss(const torch::Tensor& log_alpha, const torch::Tensor& log_pi,
                             double target_entropy) {
  return -(log_alpha * (log_pi.detach() + target_entropy)).mean();
}

torch::Tensor sac_soft_target(const torch::Tensor& rewards, const torch::Tensor& terminated,
                              const torch::Tensor& next_q, const torch::Tensor& next_log_pi,
                              const torch::Tensor& alpha, double gamma) {
  const torch::Tensor soft_q = std::get<0>(next_q.min(0)) - alpha * next_log_pi;
  return rewards + gamma * (1.0 - terminated) * soft_q;
}

torch::Tensor sac_critic_losses(const torch::Tensor& q, const torch::Tensor& target) {
  return (q - target.unsqueeze(0)).square().mean(1);
}

torch::Tensor sac_actor_loss(const torch::Tensor& alpha, const torch::Tensor& log_pi,
                             const torch::Tensor& q_pi) {
  return (alpha * log_pi - std::get<0>(q_pi.min(0))).mean();
}

namespace {

// Reads a number; UserError naming the hyperparameter otherwise.
double parse_double(const std::string& name, std::string_view text) {
  double value = 0;
  const auto result = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || result.ec != std::errc() || result.ptr != text.data() + text.size()) {
    throw UserError("sac: " + name + " '" + std::string(text) +
                    "': expected auto, auto_<number> or a number");
  }
  return value;
}

// The policy: u ~ N(mean(s), std(s)), a = tanh(u), with mean and log std from one MLP.
class SquashedGaussianActorImpl : public torch::nn::Module {
 public:
  SquashedGaussianActorImpl(const ObsShape& shape, int action_size,
                            const OffPolicyNetworkConfig& config, at::Generator& generator) {
    encoder_ = register_module("encoder", MultiInputEncoder(shape, config.cnn_features));
    const int features = encoder_->output_size();
    latent_ = register_module("latent", make_mlp(features, config.pi_layers, config.activation));
    const int last = config.pi_layers.empty() ? features : config.pi_layers.back();
    mean_ = register_module("mean", torch::nn::Linear(last, action_size));
    log_std_ = register_module("log_std", torch::nn::Linear(last, action_size));
    for (const auto& child : children()) init_layers(*child, 1.0, /*orthogonal=*/false, generator);
  }

  // The deterministic action tanh(mean(s)).
  torch::Tensor mean_action(const ObsBatch& observation) {
    return torch::tanh(mean_(latent_->forward(encoder_->forward(observation))));
  }

  // a = tanh(mean + std * eps), eps ~ N(0, I), and log pi(a|s) by the change of variables:
  //   log pi(a|s) = sum_j [log N(u_j; mean_j, std_j) - log(1 - tanh(u_j)^2)],
  // with log(1 - tanh(u)^2) = 2 (log 2 - u - softplus(-2u)), exact and stable for large |u|.
  std::pair<torch::Tensor, torch::Tensor> sample(const ObsBatch& observation,
                                                 at::Generator& generator) {
    const torch::Tensor h = latent_->forward(encoder_->forward(observation));
    return squashed_gaussian_sample(mean_(h), log_std_(h), generator);
  }

 private:
  MultiInputEncoder encoder_{nullptr};
  torch::nn::Sequential latent_{nullptr};
  torch::nn::Linear mean_{nullptr}, log_std_{nullptr};
};
TORCH_MODULE(SquashedGaussianActor);

using SacSettings = OffPolicySettings<SacConfig>;

class Sac final : public OffPolicyLearner {
 public:
  Sac(VecEnv& env, const LearnerOptions& options)
      : Sac(env, options,
            parse_off_policy_settings("sac", options, SacConfig{}, sac_loop_defaults())) {}

 private:
  Sac(VecEnv& env, const LearnerOptions& options, SacSettings settings)
      : OffPolicyLearner("sac", env, options, settings.loop, settings.observation, settings.text),
        settings_(std::move(settings)),
        config_(settings_.own),
        loop_(settings_.loop),
        actor_(shape(), action_size(), settings_.networks, generator()),
        critic_(shape(), action_size(), checked_critics(), settings_.networks, generator()),
        critic_target_(shape(), action_size(), config_.n_critics, settings_.networks, generator()),
        actor_parameters_(*actor_),
        critic_parameters_(*critic_),
        target_parameters_(*critic_target_),
        actor_optimizer_(std::vector<torch::Tensor>{actor_parameters_.tensor()},
                         torch::optim::AdamOptions(loop_.learning_rate)),
        critic_optimizer_(std::vector<torch::Tensor>{critic_parameters_.tensor()},
                          torch::optim::AdamOptions(loop_.learning_rate)),
        log_alpha_(torch::full({1}, std::log(initial_alpha()), torch::kFloat32)),
        alpha_optimizer_(std::vector<torch::Tensor>{log_alpha_.requires_grad_(learn_alpha_)},
                         torch::optim::AdamOptions(loop_.learning_rate)) {
    // Target entropy: -dim(A) by default (Haarnoja et al.'s heuristic).
    target_entropy_ = config_.target_entropy == "auto"
                          ? -static_cast<double>(action_size())
                          : parse_double("target_entropy", config_.target_entropy);
    if (config_.target_update_interval < 1) {
      throw UserError("sac: target_update_interval must be positive");
    }
    polyak_update(target_parameters_.tensor(), critic_parameters_.tensor(), 1.0);  // Q' = Q
    checkpoint_module("actor", *actor_);
    checkpoint_module("critic", *critic_);
    checkpoint_module("critic_target", *critic_target_);
    checkpoint_optimizer("actor_optimizer", actor_optimizer_);
    checkpoint_optimizer("critic_optimizer", critic_optimizer_);
    checkpoint_optimizer("alpha_optimizer", alpha_optimizer_);
    checkpoint_tensor("log_alpha", log_alpha_);
  }

  int checked_critics() const {
    if (config_.n_critics < 1) throw UserError("sac: n_critics must be positive");
    return config_.n_critics;
  }

  // alpha's starting value, and whether it is learned (sets learn_alpha_).
  double initial_alpha() {
    const std::string& text = config_.ent_coef;
    learn_alpha_ = text.starts_with("auto");
    double alpha = 1.0;
    if (text.starts_with("auto_")) {
      alpha = parse_double("ent_coef", std::string_view(text).substr(5));
    } else if (!learn_alpha_) {
      alpha = parse_double("ent_coef", text);
    } else if (text != "auto") {
      parse_double("ent_coef", text);  // "autoX": throws
    }
    if (!(alpha > 0)) throw UserError("sac: ent_coef must be positive");
    return alpha;
  }

  torch::Tensor policy_action(const ObsBatch& observation, bool deterministic) override {
    if (deterministic) return actor_->mean_action(observation);
    return actor_->sample(observation, generator()).first;
  }

  ActorCopy copy_actor() override {
    // The first refresh overwrites the copy's initial values: any generator will do.
    at::Generator unused = at::make_generator<at::CPUGeneratorImpl>(0);
    SquashedGaussianActor copy(shape(), action_size(), settings_.networks, unused);
    return {.source = actor_.ptr().get(),
            .copy = copy.ptr(),
            .explore = [copy](const ObsBatch& observation, at::Generator& generator) mutable {
              return copy->sample(observation, generator).first;
            }};
  }

  // Q(s, pi(s)) at the deterministic action, the minimum over the critics (as the targets).
  torch::Tensor state_value(const ObsBatch& observation) override {
    return std::get<0>(critic_->forward(observation, actor_->mean_action(observation)).min(0));
  }

  void train(const ReplayBuffer::Sample& batch, long update) override {
    // Reparameterised actions for s, and the temperature step on them.
    auto [pi_actions, log_pi] = actor_->sample(batch.observations, generator());
    const torch::Tensor alpha = log_alpha_.detach().exp();
    if (learn_alpha_) {
      const torch::Tensor alpha_loss = sac_alpha_loss(log_alpha_, log_pi, target_entropy_);
      alpha_optimizer_.zero_grad();
      alpha_loss.backward();
      average_gradients(sync(), log_alpha_.grad());
      alpha_optimizer_.step();
      record("alpha_loss", alpha_loss.item<double>());
    }

    // Soft Bellman target from the target critics, bootstrapping unless terminated.
    torch::Tensor target;
    {
      torch::NoGradGuard no_grad;
      auto [next_actions, next_log_pi] = actor_->sample(batch.next_observations, generator());
      target = sac_soft_target(batch.rewards, batch.terminated,
                               critic_target_->forward(batch.next_observations, next_actions),
                               next_log_pi, alpha, loop_.gamma);
    }

    // Critics: regress every Q on the target.
    const torch::Tensor q = critic_->forward(batch.observations, batch.actions);
    const torch::Tensor q_losses = sac_critic_losses(q, target);
    const torch::Tensor qf_loss = 0.5 * q_losses.sum();
    critic_parameters_.zero_grad();
    qf_loss.backward();
    average_gradients(sync(), critic_parameters_.tensor().grad());
    critic_optimizer_.step();

    // Actor: maximise min Q minus alpha log pi (the critics pass gradients to the actions only).
    torch::Tensor actor_loss;
    {
      const FrozenParameters frozen(*critic_);
      actor_loss = sac_actor_loss(alpha, log_pi, critic_->forward(batch.observations, pi_actions));
      actor_parameters_.zero_grad();
      actor_loss.backward();
    }
    average_gradients(sync(), actor_parameters_.tensor().grad());
    actor_optimizer_.step();

    if (update % config_.target_update_interval == 0) {
      polyak_update(target_parameters_.tensor(), critic_parameters_.tensor(), loop_.tau);
    }

    record("qf_loss", qf_loss.item<double>());
    record("qf1_loss", q_losses[0].item<double>());
    record("qf1_values", q[0].mean().item<double>());
    record("actor_loss", actor_loss.item<double>());
    record("alpha", alpha.item<double>());
    record("entropy", -log_pi.mean().item<double>());
  }

  const SacSettings settings_;
  const SacConfig& config_;
  const OffPolicyConfig& loop_;
  bool learn_alpha_ = true;  // set by initial_alpha(), before log_alpha_ is built
  double target_entropy_ = 0;
  SquashedGaussianActor actor_;
  Critic critic_, critic_target_;
  PackedParameters actor_parameters_, critic_parameters_, target_parameters_;
  torch::optim::Adam actor_optimizer_, critic_optimizer_;
  torch::Tensor log_alpha_;
  torch::optim::Adam alpha_optimizer_;
};

}  // namespace

std::unique_ptr<Learner> make_sac(VecEnv& env, const LearnerOptions& options) {
  return std::make_unique<Sac>(env, options);
}

}  // namespace cradle::learn

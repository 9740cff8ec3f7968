// TD3, top to bottom (one update; OffPolicyLearner runs the replay loop around it):
//   sample a minibatch (s, a, r, s', terminated) from the replay buffer
//   a' = clip(mu'(s') + clip(N(0, target_policy_noise), -c, c), -1, 1)   (target smoothing)
//   y = r + gamma (1 - terminated) min_i Q'_i(s', a')                     (clipped double Q)
//   J(Q) = sum_i mean((Q_i(s, a) - y)^2)                one Adam step on the critics
//   every policy_delay updates:
//     J(mu) = -mean(Q_1(s, mu(s)))                      one Adam step on the actor
//     Q' <- tau Q + (1 - tau) Q',  mu' <- tau mu + (1 - tau) mu'
// Exploration: a = clip(mu(s) + N(0, exploration_noise), -1, 1).
// Data-parallel (learn/grad_sync.h): the critics' and the actor's gradients are averaged over the
// ranks before their Adam steps; the delay counts updates, which every rank makes alike.
#include "learn/td3.h"

#include <torch/torch.h>

#include "core/error.h"
#include "learn/grad_tensors.h"

namespace cradle::learn {

void Td3Config::bind(Hyperparameters& table) {
  if (!ddpg) {
    table.add("policy_delay", &policy_delay, "critic updates per actor and target update");
    table.add("target_policy_noise", &target_policy_noise, "std of the target smoothing noise");
    table.add("target_noise_clip", &target_noise_clip, "clip of the target smoothing noise");
    table.add("n_critics", &n_critics, "Q networks (targets take their minimum)");
  }
  table.add("exploration_noise", &exploration_noise, "std of the Gaussian exploration noise");
}

OffPolicyConfig td3_loop_defaults() {
  return {.learning_rate = 1e-3,     // SB3 TD3/DDPG learning_rate
          .buffer_size = 1'000'000,  // SB3 buffer_size
          .learning_starts = 100,    // SB3 learning_starts
          .batch_size = 256,         // SB3 >= 2.3 batch_size (100 before)
          .tau = 0.005,              // SB3 tau
          .gamma = 0.99,             // SB3 gamma
          .train_freq = 1,           // SB3 >= 2.3 train_freq (one episode before)
          .gradient_steps = 1};      // SB3 >= 2.3 gradient_steps (-1 before)
}

namespace {

// mu(s) = tanh(Linear(MLP(encoder(s)))): actions in [-1, 1].
class DeterministicActorImpl : public torch::nn::Module {
 public:
  DeterministicActorImpl(const ObsShape& shape, int action_size,
                         const OffPolicyNetworkConfig& config, at::Generator& generator) {
    encoder_ = register_module("encoder", MultiInputEncoder(shape, config.cnn_features));
    const int features = encoder_->output_size();
    latent_ = register_module("latent", make_mlp(features, config.pi_layers, config.activation));
    const int last = config.pi_layers.empty() ? features : config.pi_layers.back();
    action_ = register_module("action", torch::nn::Linear(last, action_size));
    for (const auto& child : children()) init_layers(*child, 1.0, /*orthogonal=*/false, generator);
  }
  torch::Tensor forward(const ObsBatch& observation) {
    return torch::tanh(action_(latent_->forward(encoder_->forward(observation))));
  }

 private:
  MultiInputEncoder encoder_{nullptr};
  torch::nn::Sequential latent_{nullptr};
  torch::nn::Linear action_{nullptr};
};
TORCH_MODULE(DeterministicActor);

using Td3Settings = OffPolicySettings<Td3Config>;

// Checks the algorithm's own settings (UserError naming the first bad one).
const Td3Settings& checked(std::string_view algorithm, const Td3Settings& settings) {
  const Td3Config& c = settings.own;
  const std::string name(algorithm);
  if (c.policy_delay < 1 || c.n_critics < 1) {
    throw UserError(name + ": policy_delay and n_critics must be positive");
  }
  if (!(c.target_policy_noise >= 0 && c.target_noise_clip >= 0 && c.exploration_noise >= 0)) {
    throw UserError(name + ": target_policy_noise, target_noise_clip and exploration_noise " +
                    "must be >= 0");
  }
  return settings;
}

class Td3 final : public OffPolicyLearner {
 public:
  Td3(std::string_view algorithm, VecEnv& env, const LearnerOptions& options, const Td3Config& own)
      : Td3(algorithm, env, options,
            checked(algorithm,
                    parse_off_policy_settings(algorithm, options, own, td3_loop_defaults()))) {}

 private:
  Td3(std::string_view algorithm, VecEnv& env, const LearnerOptions& options, Td3Settings settings)
      : OffPolicyLearner(std::string(algorithm), env, options, settings.loop, settings.observation,
                         settings.text),
        settings_(std::move(settings)),
        config_(settings_.own),
        loop_(settings_.loop),
        actor_(shape(), action_size(), settings_.networks, generator()),
        actor_target_(shape(), action_size(), settings_.networks, generator()),
        critic_(shape(), action_size(), config_.n_critics, settings_.networks, generator()),
        critic_target_(shape(), action_size(), config_.n_critics, settings_.networks, generator()),
        actor_parameters_(*actor_),
        actor_target_parameters_(*actor_target_),
        critic_parameters_(*critic_),
        critic_target_parameters_(*critic_target_),
        actor_optimizer_(std::vector<torch::Tensor>{actor_parameters_.tensor()},
                         torch::optim::AdamOptions(loop_.learning_rate)),
        critic_optimizer_(std::vector<torch::Tensor>{critic_parameters_.tensor()},
                          torch::optim::AdamOptions(loop_.learning_rate)) {
    // The targets start as copies.
    polyak_update(actor_target_parameters_.tensor(), actor_parameters_.tensor(), 1.0);
    polyak_update(critic_target_parameters_.tensor(), critic_parameters_.tensor(), 1.0);
    checkpoint_module("actor", *actor_);
    checkpoint_module("actor_target", *actor_target_);
    checkpoint_module("critic", *critic_);
    checkpoint_module("critic_target", *critic_target_);
    checkpoint_optimizer("actor_optimizer", actor_optimizer_);
    checkpoint_optimizer("critic_optimizer", critic_optimizer_);
  }

  torch::Tensor policy_action(const ObsBatch& observation, bool deterministic) override {
    const torch::Tensor mu = actor_->forward(observation);
    if (deterministic || config_.exploration_noise == 0) return mu;
    const torch::Tensor noise = torch::randn(mu.sizes(), generator(), torch::kFloat32);
    return torch::clamp(mu + config_.exploration_noise * noise, -1.0, 1.0);
  }

  ActorCopy copy_actor() override {
    // The first refresh overwrites the copy's initial values: any generator will do.
    at::Generator unused = at::make_generator<at::CPUGeneratorImpl>(0);
    DeterministicActor copy(shape(), action_size(), settings_.networks, unused);
    const double noise = config_.exploration_noise;
    return {
        .source = actor_.ptr().get(),
        .copy = copy.ptr(),
        .explore = [copy, noise](const ObsBatch& observation, at::Generator& generator) mutable {
          const torch::Tensor mu = copy->forward(observation);
          if (noise == 0) return mu;
          return torch::clamp(mu + noise * torch::randn(mu.sizes(), generator, torch::kFloat32),
                              -1.0, 1.0);
        }};
  }

  // Q(s, mu(s)), the minimum over the critics (as the targets, and as SAC's value; DDPG has one).
  torch::Tensor state_value(const ObsBatch& observation) override {
    return std::get<0>(critic_->forward(observation, actor_->forward(observation)).min(0));
  }

  void train(const ReplayBuffer::Sample& batch, long update) override {
    // Target: the target actor's smoothed action, the minimum of the target critics.
    torch::Tensor target;
    {
      torch::NoGradGuard no_grad;
      torch::Tensor next_actions = actor_target_->forward(batch.next_observations);
      if (config_.target_policy_noise > 0) {
        const torch::Tensor noise =
            torch::randn(next_actions.sizes(), generator(), torch::kFloat32)
                .mul_(config_.target_policy_noise)
                .clamp_(-config_.target_noise_clip, config_.target_noise_clip);
        next_actions = torch::clamp(next_actions + noise, -1.0, 1.0);
      }
      const torch::Tensor next_q =
          std::get<0>(critic_target_->forward(batch.next_observations, next_actions).min(0));
      target = batch.rewards + loop_.gamma * (1.0 - batch.terminated) * next_q;
    }

    // Critics: regress every Q on the target.
    const torch::Tensor q = critic_->forward(batch.observations, batch.actions);
    const torch::Tensor q_losses = (q - target.unsqueeze(0)).square().mean(1);
    const torch::Tensor qf_loss = q_losses.sum();
    critic_parameters_.zero_grad();
    qf_loss.backward();
    average_gradients(sync(), critic_parameters_.tensor().grad());
    critic_optimizer_.step();
    record("qf_loss", qf_loss.item<double>());
    record("qf1_loss", q_losses[0].item<double>());
    record("qf1_values", q[0].mean().item<double>());

    // Delayed: the actor ascends Q_1, then the targets follow.
    if (update % config_.policy_delay != 0) return;
    torch::Tensor actor_loss;
    {
      const FrozenParameters frozen(*critic_);  // gradients to the actions only
      actor_loss = -critic_->q1(batch.observations, actor_->forward(batch.observations)).mean();
      actor_parameters_.zero_grad();
      actor_loss.backward();
    }
    average_gradients(sync(), actor_parameters_.tensor().grad());
    actor_optimizer_.step();
    polyak_update(critic_target_parameters_.tensor(), critic_parameters_.tensor(), loop_.tau);
    polyak_update(actor_target_parameters_.tensor(), actor_parameters_.tensor(), loop_.tau);
    record("actor_loss", actor_loss.item<double>());
  }

  const Td3Settings settings_;
  const Td3Config& config_;
  const OffPolicyConfig& loop_;
  DeterministicActor actor_, actor_target_;
  Critic critic_, critic_target_;
  PackedParameters actor_parameters_, actor_target_parameters_, critic_parameters_,
      critic_target_parameters_;
  torch::optim::Adam actor_optimizer_, critic_optimizer_;
};

}  // namespace

std::unique_ptr<Learner> make_td3_variant(std::string_view algorithm, VecEnv& env,
                                          const LearnerOptions& options, const Td3Config& own) {
  return std::make_unique<Td3>(algorithm, env, options, own);
}

std::unique_ptr<Learner> make_td3(VecEnv& env, const LearnerOptions& options) {
  return make_td3_variant("td3", env, options, Td3Config{});
}

}  // namespace cradle::learn

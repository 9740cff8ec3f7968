#include "learn/meta/context_sac.h"

#include <cmath>

#include "core/error.h"
#include "learn/checkpoint.h"
#include "learn/grad_tensors.h"
#include "learn/meta/sance.h"
#include "learn/sac.h"

namespace cradle::learn::meta {

void SamiConfig::bind(Hyperparameters& table) {
  table.add("learning_rate", &learning_rate, "Adam step size (actor, critic, encoder, alpha)");
  table.add("gamma", &gamma, "discount factor");
  table.add("tau", &tau, "critic target Polyak coefficient");
  table.add("encoder_tau", &encoder_tau, "encoder target Polyak coefficient");
  table.add("buffer_size", &buffer_size, "trajectories stored per training env");
  table.add("batch_size", &batch_size, "trajectories per RL batch");
  table.add("contrast_batch_size", &contrast_batch_size, "trajectories per contrastive batch");
  table.add("train_freq", &train_freq, "vector steps between trainings");
  table.add("gradient_steps", &gradient_steps, "gradient steps per training");
  table.add("learning_starts", &learning_starts, "random env steps per env before training");
  table.add("net_arch", &net_arch, "actor and critic hidden sizes");
  table.add("lstm_hidden", &lstm_hidden, "context encoder LSTM units");
  table.add("context_size", &context_size, "context dimensions");
  table.add("temperature", &temperature, "InfoNCE temperature");
  table.add("neg_ratio", &neg_ratio, "share of negatives in a contrastive batch");
  table.add("adversarial_loss_coef", &adversarial_loss_coef, "lambda of the SaNCE weight");
  table.add("use_weighted_info_nce", &use_weighted_info_nce, "map keys by the matrix W");
  table.add("update_threads", &update_threads, "LibTorch threads in updates (0: unchanged)");
}

void SamiConfig::check() const {
  const auto need = [](bool ok, const std::string& what) {
    if (!ok) throw UserError("sami: hyperparameter " + what);
  };
  need(encoder_tau > 0 && encoder_tau <= 1, "encoder_tau: expected 0 < encoder_tau <= 1");
  need(contrast_batch_size >= 2 && contrast_batch_size <= 100000,
       "contrast_batch_size: expected 2 <= contrast_batch_size <= 100000");
  need(batch_size >= 1 && batch_size <= 100000, "batch_size: expected 1 <= batch_size <= 100000");
  need(net_arch.size() >= 1, "net_arch: expected at least one layer");
  for (const int size : net_arch)
    need(size >= 1 && size <= 65536, "net_arch: expected every layer size in 1..65536");
  need(lstm_hidden >= 1 && lstm_hidden <= 65536, "lstm_hidden: expected 1 <= lstm_hidden <= 65536");
  need(context_size >= 1 && context_size <= 4096,
       "context_size: expected 1 <= context_size <= 4096");
  need(temperature > 0 && temperature <= 1e3, "temperature: expected 0 < temperature <= 1000");
  need(neg_ratio > 0 && neg_ratio < 1, "neg_ratio: expected 0 < neg_ratio < 1");
  need(adversarial_loss_coef >= 0 && adversarial_loss_coef <= 1e6,
       "adversarial_loss_coef: expected 0 <= adversarial_loss_coef <= 1e6");
  need(update_threads >= 0 && update_threads <= 1024,
       "update_threads: expected 0 <= update_threads <= 1024");
}

std::string apply_sami_hyperparameters(SamiConfig& config,
                                       const std::map<std::string, std::string>& overrides) {
  Hyperparameters table;
  config.bind(table);
  table.apply(overrides);
  config.check();
  return table.to_text();
}

ContextActorImpl::ContextActorImpl(int input, int action_size, const std::vector<int>& layers,
                                   at::Generator& generator) {
  latent_ = register_module("latent", make_mlp(input, layers, "relu"));
  mean_ = register_module("mean", torch::nn::Linear(layers.back(), action_size));
  log_std_ = register_module("log_std", torch::nn::Linear(layers.back(), action_size));
  for (const auto& child : children()) init_layers(*child, 1.0, /*orthogonal=*/false, generator);
}

torch::Tensor ContextActorImpl::mean_action(const torch::Tensor& input) {
  return torch::tanh(mean_(latent_->forward(input)));
}

std::pair<torch::Tensor, torch::Tensor> ContextActorImpl::sample(const torch::Tensor& input,
                                                                 at::Generator& generator) {
  const torch::Tensor h = latent_->forward(input);
  return squashed_gaussian_sample(mean_(h), log_std_(h), generator);
}

namespace {

OffPolicyNetworkConfig critic_config(const SamiConfig& config) {
  OffPolicyNetworkConfig networks;
  networks.qf_layers = config.net_arch;
  return networks;
}

// The values, then the memory of the context encoders (an LSTM of 4 gates over [input, hidden],
// online and target, with gradients and Adam moments): lstm_hidden=65536 is a one-line error,
// not bad_alloc. The actor and critics check theirs as they are built (make_mlp, Critic).
const SamiConfig& checked(const SamiConfig& config, int obs_size, int action_size) {
  config.check();
  const double h = config.lstm_hidden;
  const double lstm = 4.0 * h * (obs_size + action_size + h) + (h + 1) * config.context_size;
  check_network_memory(
      "sami: context encoders of lstm_hidden " + std::to_string(config.lstm_hidden), 2 * lstm);
  return config;
}

// Rows of a [T, B, ...] tensor's first T - 1 steps, flattened to [(T - 1) B, ...], at `rows`.
torch::Tensor steps_at(const torch::Tensor& x, long begin, const torch::Tensor& rows) {
  const long t = x.size(0) - 1;
  return x.narrow(0, begin, t).reshape({t * x.size(1), -1}).index_select(0, rows);
}

// Data-parallel: the gradients an optimiser steps with (the encoder's LSTM, heads and W), averaged
// over the ranks. A tensor no loss has reached yet has none on every rank alike (every step that
// reaches one is agreed on), so the ranks reduce the same tensors.
void average_optimizer_gradients(GradSync* sync, torch::optim::Optimizer& optimizer) {
  if (!distributed(sync)) return;
  for (auto& group : optimizer.param_groups()) {
    for (const torch::Tensor& p : group.params()) average_gradients(sync, p.grad());
  }
}

}  // namespace

ContextSac::ContextSac(std::string method, int obs_size, int action_size, const SamiConfig& config,
                       std::uint64_t seed)
    : method_(std::move(method)),
      contrast_(method_contrast(method_)),
      config_(checked(config, obs_size, action_size)),
      obs_size_(obs_size),
      action_size_(action_size),
      generator_(at::make_generator<at::CPUGeneratorImpl>(seed)),
      encoders_(action_size + obs_size, config_.lstm_hidden, config_.context_size,
                config_.learning_rate, generator_),
      actor_(obs_size + config_.context_size, action_size, config_.net_arch, generator_),
      critic_(ObsShape{obs_size + config_.context_size}, action_size, 2, critic_config(config_),
              generator_),
      critic_target_(ObsShape{obs_size + config_.context_size}, action_size, 2,
                     critic_config(config_), generator_),
      actor_parameters_(*actor_),
      critic_parameters_(*critic_),
      target_parameters_(*critic_target_),
      actor_optimizer_(std::vector<torch::Tensor>{actor_parameters_.tensor()},
                       torch::optim::AdamOptions(config_.learning_rate)),
      critic_optimizer_(std::vector<torch::Tensor>{critic_parameters_.tensor()},
                        torch::optim::AdamOptions(config_.learning_rate)),
      log_alpha_(torch::zeros({1}, torch::kFloat32)),  // alpha starts at 1
      alpha_optimizer_(std::vector<torch::Tensor>{log_alpha_.requires_grad_(true)},
                       torch::optim::AdamOptions(config_.learning_rate)),
      target_entropy_(-static_cast<double>(action_size)) {
  SamiConfig copy = config_;
  text_ = "method = " + method_ + "\n" + apply_sami_hyperparameters(copy, {});
  polyak_update(target_parameters_.tensor(), critic_parameters_.tensor(), 1.0);  // Q' = Q
}

ContextSac::Losses ContextSac::update(const TrajectoryReplay& replay, Rng& rng) {
  const ScopedTorchThreads threads(config_.update_threads);
  Losses out;
  ++updates_;

  // The RL batch: whole trajectories, contexts from both encoders in one LSTM call each.
  const TrajectoryReplay::Batch batch = replay.gather(sample_even(replay, config_.batch_size, rng));
  const torch::Tensor input = batch.encoder_input();  // [T, B, in]
  const torch::Tensor contexts = encoders_.online->forward(input);
  torch::Tensor next_contexts;
  {
    torch::NoGradGuard no_grad;
    next_contexts = encoders_.target->forward(input);
  }
  // Transitions t < len, as rows of the flattened [(T - 1) B] steps.
  const torch::Tensor valid = batch.valid.t().narrow(0, 0, input.size(0) - 1).reshape({-1});
  const torch::Tensor rows = valid.nonzero().squeeze(1);
  const torch::Tensor obs = batch.observations.transpose(0, 1);  // [T, B, obs]
  const torch::Tensor states = torch::cat({steps_at(obs, 0, rows), steps_at(contexts, 0, rows)}, 1);
  const torch::Tensor next_states =
      torch::cat({steps_at(obs, 1, rows), steps_at(next_contexts, 1, rows)}, 1);
  const torch::Tensor actions = steps_at(batch.actions.transpose(0, 1), 0, rows);
  const torch::Tensor rewards = steps_at(batch.rewards.t().unsqueeze(2), 0, rows).squeeze(1);
  const torch::Tensor terminated = steps_at(batch.terminated.t().unsqueeze(2), 0, rows).squeeze(1);
  const torch::Tensor detached = states.detach();

  // Temperature step on reparameterised actions of the detached states.
  auto [pi_actions, log_pi] = actor_->sample(detached, generator_);
  const torch::Tensor alpha = log_alpha_.detach().exp();
  const torch::Tensor alpha_loss = sac_alpha_loss(log_alpha_, log_pi, target_entropy_);
  alpha_optimizer_.zero_grad();
  alpha_loss.backward();
  average_gradients(sync_, log_alpha_.grad());
  alpha_optimizer_.step();

  // Soft Bellman target at (o_{t+1}, c'_{t+1}).
  torch::Tensor target;
  {
    torch::NoGradGuard no_grad;
    auto [next_actions, next_log_pi] = actor_->sample(next_states, generator_);
    target = sac_soft_target(rewards, terminated,
                             critic_target_->forward(ObsBatch{next_states, {}}, next_actions),
                             next_log_pi, alpha, config_.gamma);
  }

  // Critics, and the encoder through c_t.
  const torch::Tensor q = critic_->forward(ObsBatch{states, {}}, actions);
  const torch::Tensor q_losses = sac_critic_losses(q, target);
  const torch::Tensor critic_loss = 0.5 * q_losses.sum();
  critic_parameters_.zero_grad();
  encoders_.optimizer.zero_grad();
  critic_loss.backward();
  average_gradients(sync_, critic_parameters_.tensor().grad());
  average_optimizer_gradients(sync_, encoders_.optimizer);
  critic_optimizer_.step();
  encoders_.optimizer.step();

  // Actor on the detached contexts.
  torch::Tensor actor_loss;
  {
    const FrozenParameters frozen(*critic_);
    actor_loss =
        sac_actor_loss(alpha, log_pi, critic_->forward(ObsBatch{detached, {}}, pi_actions));
    actor_parameters_.zero_grad();
    actor_loss.backward();
  }
  average_gradients(sync_, actor_parameters_.tensor().grad());
  actor_optimizer_.step();
  polyak_update(target_parameters_.tensor(), critic_parameters_.tensor(), config_.tau);

  // The method's contrastive step on w * SaNCE.
  if (contrast_ != Contrast::kNone) {
    const ContrastSample sample =
        sample_contrast(contrast_, replay, config_.contrast_batch_size, config_.neg_ratio, rng);
    out.weight =
        sance_weight(config_.adversarial_loss_coef, sample.positive_return, sample.negative_return);
    // Data-parallel: the step runs on every rank when any has a weight (a rank without one adds
    // a zero gradient to the average).
    if (agree_max(sync_, out.weight > 0 ? 1.0 : 0.0) > 0) {
      const TrajectoryReplay::Batch positives = replay.gather(sample.positives);
      const TrajectoryReplay::Batch negatives = replay.gather(sample.negatives);
      const torch::Tensor positive_input = positives.encoder_input();
      const torch::Tensor queries = encoders_.online->forward(positive_input);
      torch::Tensor positive_keys, negative_keys;
      {
        torch::NoGradGuard no_grad;
        positive_keys = encoders_.target->forward(positive_input);
        negative_keys = encoders_.target->forward(negatives.encoder_input());
      }
      // Steps from the terminal step on are zeroed (SaMI's stored done flag).
      const auto live = [](const TrajectoryReplay::Batch& b) {
        const long t = b.observations.size(1);
        return (torch::arange(t).unsqueeze(1) < (b.lengths - 1).unsqueeze(0)).to(torch::kFloat32);
      };
      const torch::Tensor loss =
          sance_loss(queries, positive_keys, negative_keys, live(positives), live(negatives),
                     config_.temperature,
                     config_.use_weighted_info_nce ? encoders_.bilinear->weight : torch::Tensor());
      encoders_.optimizer.zero_grad();
      (out.weight * loss).backward();
      average_optimizer_gradients(sync_, encoders_.optimizer);
      encoders_.optimizer.step();
      out.sance = loss.item<double>();
    }
  }
  encoders_.update_target(config_.encoder_tau);

  out.critic = critic_loss.item<double>();
  out.actor = actor_loss.item<double>();
  out.alpha = alpha.item<double>();
  out.alpha_loss = alpha_loss.item<double>();
  out.entropy = -log_pi.mean().item<double>();
  return out;
}

void ContextSac::Streams::reset(int row) {
  state.first.select(1, row).zero_();
  state.second.select(1, row).zero_();
  prev_actions.select(0, row).zero_();
}

ContextSac::Streams ContextSac::streams(int count) const {
  const int hidden = config_.lstm_hidden;
  return {{torch::zeros({1, count, hidden}), torch::zeros({1, count, hidden})},
          torch::zeros({count, action_size_})};
}

std::pair<torch::Tensor, torch::Tensor> ContextSac::act(const torch::Tensor& observations,
                                                        Streams& streams, bool deterministic) {
  torch::NoGradGuard no_grad;
  const torch::Tensor contexts =
      encoders_.online->step(torch::cat({streams.prev_actions, observations}, 1), streams.state);
  const torch::Tensor input = torch::cat({observations, contexts}, 1);
  const torch::Tensor actions =
      deterministic ? actor_->mean_action(input) : actor_->sample(input, generator_).first;
  streams.prev_actions.copy_(actions);
  return {actions, contexts};
}

void ContextSac::save(const std::filesystem::path& file, long steps) const {
  const CheckpointInfo header{.algorithm = "sami_" + method_, .config = text_, .steps = steps};
  write_checkpoint(file, header, [&](torch::serialize::OutputArchive& archive) { write(archive); });
}

long ContextSac::load(const std::filesystem::path& file) {
  const CheckpointInfo info = read_checkpoint(
      file, "sami_" + method_,
      [&](const CheckpointInfo&, torch::serialize::InputArchive& archive) { read(archive)(); });
  return info.steps;
}

void ContextSac::write(torch::serialize::OutputArchive& archive) const {
  write_module(archive, "actor", *actor_);
  write_module(archive, "critic", *critic_);
  write_module(archive, "critic_target", *critic_target_);
  write_module(archive, "encoder", *encoders_.online);
  write_module(archive, "encoder_target", *encoders_.target);
  write_module(archive, "bilinear", *encoders_.bilinear);
  write_optimizer(archive, "actor_optimizer", actor_optimizer_);
  write_optimizer(archive, "critic_optimizer", critic_optimizer_);
  write_optimizer(archive, "alpha_optimizer", alpha_optimizer_);
  write_optimizer(archive, "encoder_optimizer", encoders_.optimizer);
  archive.write("log_alpha", log_alpha_.detach());
  write_generator(archive, "generator", generator_);
  archive.write("updates", torch::tensor({updates_}, torch::kInt64));
}

std::function<void()> ContextSac::read(torch::serialize::InputArchive& archive) {
  // Every module's shape is checked before anything changes.
  std::vector<std::function<void()>> copies;
  copies.push_back(stage_module(archive, "actor", *actor_));
  check_critic_format(archive, "critic");
  copies.push_back(stage_module(archive, "critic", *critic_));
  copies.push_back(stage_module(archive, "critic_target", *critic_target_));
  copies.push_back(stage_module(archive, "encoder", *encoders_.online));
  copies.push_back(stage_module(archive, "encoder_target", *encoders_.target));
  copies.push_back(stage_module(archive, "bilinear", *encoders_.bilinear));
  return [this, &archive, copies = std::move(copies)] {
    for (const auto& copy : copies) copy();
    read_optimizer(archive, "actor_optimizer", actor_optimizer_);
    read_optimizer(archive, "critic_optimizer", critic_optimizer_);
    read_optimizer(archive, "alpha_optimizer", alpha_optimizer_);
    read_optimizer(archive, "encoder_optimizer", encoders_.optimizer);
    torch::Tensor log_alpha, updates;
    archive.read("log_alpha", log_alpha);
    {
      torch::NoGradGuard no_grad;
      log_alpha_.copy_(log_alpha);
    }
    read_generator(archive, "generator", generator_);
    archive.read("updates", updates);
    updates_ = updates.item<long>();
  };
}

std::vector<torch::Tensor> ContextSac::parameters() const {
  std::vector<torch::Tensor> out;
  const auto add = [&out](const torch::nn::Module& module) {
    for (const torch::Tensor& p : module.parameters()) out.push_back(p);
  };
  add(*actor_);
  add(*critic_);
  add(*critic_target_);
  add(*encoders_.online);
  add(*encoders_.target);
  add(*encoders_.bilinear);
  out.push_back(log_alpha_);
  return out;
}

}  // namespace cradle::learn::meta

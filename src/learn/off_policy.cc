#include "learn/off_policy.h"

#include <chrono>
#include <functional>
#include <limits>
#include <sstream>
#include <utility>

#include "core/error.h"
#include "learn/checkpoint.h"

namespace cradle::learn {

void OffPolicyConfig::bind(Hyperparameters& table) {
  table.add("learning_rate", &learning_rate, "Adam step size of every network");
  table.add("buffer_size", &buffer_size, "replay buffer capacity in transitions");
  table.add("learning_starts", &learning_starts, "transitions (random actions) before training");
  table.add("batch_size", &batch_size, "minibatch size");
  table.add("tau", &tau, "Polyak coefficient of the target networks");
  table.add("gamma", &gamma, "discount factor");
  table.add("train_freq", &train_freq, "vector steps between trainings");
  table.add("gradient_steps", &gradient_steps, "gradient steps per training");
  table.add("episode_train_freq", &episode_train_freq,
            "> 0: at each episode end, ceil(length / this) gradient steps (SpinningUp SAC)");
  table.add("report_every", &report_every, "vector steps between progress reports");
}

void OffPolicyConfig::check(std::string_view algorithm) const {
  const std::string name(algorithm);
  if (batch_size < 1 || train_freq < 1 || gradient_steps < 1 || report_every < 1) {
    throw UserError(name +
                    ": batch_size, train_freq, gradient_steps and report_every must be positive");
  }
  if (learning_starts < 0) throw UserError(name + ": learning_starts must be >= 0");
  if (episode_train_freq < 0) throw UserError(name + ": episode_train_freq must be >= 0");
  if (!(tau > 0 && tau <= 1)) throw UserError(name + ": tau must be in (0, 1]");
  if (!(gamma >= 0 && gamma <= 1)) throw UserError(name + ": gamma must be in [0, 1]");
  if (!(learning_rate > 0)) throw UserError(name + ": learning_rate must be positive");
}

void OffPolicyNetworkConfig::bind(Hyperparameters& table) {
  table.add("pi_layers", &pi_layers, "actor MLP hidden sizes, e.g. 256,256 (SB3 net_arch pi)");
  table.add("qf_layers", &qf_layers, "critic MLP hidden sizes, e.g. 256,256 (SB3 net_arch qf)");
  table.add("activation", &activation, "hidden activation: relu or tanh (SB3 activation_fn)");
  table.add("cnn_features", &cnn_features, "NatureCNN output size per image (SB3 features_dim)");
}

// ---------------------------------------------------------------------------------------------
// Critics

CriticImpl::CriticImpl(const ObsShape& shape, int action_size, int critics,
                       const OffPolicyNetworkConfig& config, at::Generator& generator) {
  encoder_ = register_module("encoder", MultiInputEncoder(shape, config.cnn_features));
  const int input = encoder_->output_size() + action_size;
  const int last = config.qf_layers.empty() ? input : config.qf_layers.back();
  for (int i = 0; i < critics; ++i) {
    torch::nn::Sequential q = make_mlp(input, config.qf_layers, config.activation);
    q->push_back(torch::nn::Linear(last, 1));
    q_.push_back(register_module("q" + std::to_string(i + 1), q));
  }
  // SB3 keeps PyTorch's default initialisation for off-policy networks. (Per child: a module
  // under construction cannot list itself.)
  for (const auto& child : children()) init_layers(*child, 1.0, /*orthogonal=*/false, generator);
}

torch::Tensor CriticImpl::forward(const ObsBatch& observation, const torch::Tensor& actions) {
  const torch::Tensor input = torch::cat({encoder_->forward(observation), actions}, 1);
  std::vector<torch::Tensor> values;
  for (auto& q : q_) values.push_back(q->forward(input).squeeze(1));
  return torch::stack(values);
}

torch::Tensor CriticImpl::q1(const ObsBatch& observation, const torch::Tensor& actions) {
  return q_[0]->forward(torch::cat({encoder_->forward(observation), actions}, 1)).squeeze(1);
}

void polyak_update(torch::Tensor& target, const torch::Tensor& online, double tau) {
  torch::NoGradGuard no_grad;
  target.mul_(1.0 - tau).add_(online, tau);
}

FrozenParameters::FrozenParameters(torch::nn::Module& module) : parameters_(module.parameters()) {
  for (torch::Tensor& p : parameters_) p.requires_grad_(false);
}

FrozenParameters::~FrozenParameters() {
  for (torch::Tensor& p : parameters_) p.requires_grad_(true);
}

// ---------------------------------------------------------------------------------------------
// The learner skeleton

namespace {

using Clock = std::chrono::steady_clock;

// The replay capacity, once the env's actions and the buffer's memory are known to be fine.
long checked_capacity(std::string_view algorithm, const VecEnv& env, long capacity,
                      const ObsShape& shape) {
  check_bounded_actions(algorithm, env.action_space());
  check_replay_memory(algorithm, capacity, shape, env.action_space().size());
  return capacity;
}

}  // namespace

OffPolicyLearner::OffPolicyLearner(std::string algorithm, VecEnv& env,
                                   const LearnerOptions& options, const OffPolicyConfig& loop,
                                   const ObservationConfig& observation, std::string text)
    : algorithm_(std::move(algorithm)),
      env_(env),
      config_(loop),
      observation_(observation),
      text_(std::move(text)),
      generator_(at::make_generator<at::CPUGeneratorImpl>(options.seed)),
      pipeline_(env.observation_space(), observation_, find_touch(env)),
      buffer_(checked_capacity(algorithm_, env, config_.buffer_size, pipeline_.shape()),
              pipeline_.shape(), env.action_space().size()),
      collector_(env, pipeline_, options.reward_hook),
      scratch_(ObsBatch::zeros(pipeline_.shape(), 1)),
      update_threads_(update_threads(options, pipeline_.shape())),
      sync_(options.sync) {}

void OffPolicyLearner::learn(long total_steps, const ProgressFn& on_progress) {
  const Clock::time_point start = Clock::now();
  const long start_steps = steps_;
  const int envs = env_.num_envs();
  collector_.start(draw_env_seed(generator_));
  torch::Tensor random = torch::zeros({envs, action_size()}, torch::kFloat32);
  records_.clear();
  double collect_seconds = 0, update_seconds = 0;  // since the last report
  std::vector<long> episode_length(envs, 0);       // episode_train_freq: steps per env
  std::vector<std::uint8_t> episode_ended(envs, 0);
  // Episode-end updates differ per rank, and every update is a collective: refused together.
  if (config_.episode_train_freq > 0 && distributed(sync_.get()))
    throw UserError("episode_train_freq > 0 cannot run distributed (ranks would update a different "
                    "number of times); use train_freq/gradient_steps");
  // Data-parallel: every rank continues from rank 0's networks.
  for (const auto& [key, module] : modules_) broadcast_module(sync_.get(), *module);
  for (const auto& [key, tensor] : tensors_) broadcast_tensor(sync_.get(), *tensor);
  while (steps_ < total_steps) {
    // Act: uniformly at random until learning_starts, then the algorithm's exploration.
    const Clock::time_point collect_start = Clock::now();
    torch::Tensor actions;
    if (steps_ < config_.learning_starts) {
      actions = random.uniform_(-1.0, 1.0, generator_);
    } else {
      torch::NoGradGuard no_grad;
      actions = policy_action(collector_.observation(), /*deterministic=*/false);
    }
    collector_.step(actions, buffer_);
    steps_ += static_cast<long>(envs) * world_size(sync_.get());  // every rank's
    ++vector_steps_;
    const Clock::time_point update_start = Clock::now();
    collect_seconds += std::chrono::duration<double>(update_start - collect_start).count();

    // Train every train_freq vector steps once the buffer holds more than learning_starts
    // (episode_train_freq > 0: at episode ends, as many updates as the episode asks).
    int updates = vector_steps_ % config_.train_freq == 0 ? config_.gradient_steps : 0;
    if (config_.episode_train_freq > 0) {
      updates = 0;
      for (int e = 0; e < envs; ++e) {
        // An autoreset step (the one after a done step) is no step of the new episode.
        if (std::exchange(episode_ended[e], 0)) continue;
        ++episode_length[e];
        if (!env_.terminated()[e] && !env_.truncated()[e]) continue;
        updates += static_cast<int>((episode_length[e] + config_.episode_train_freq - 1) /
                                    config_.episode_train_freq);
        episode_length[e] = 0;
        episode_ended[e] = 1;
      }
    }
    if (updates > 0 && ready_to_train()) {
      const ScopedTorchThreads threads(update_threads_);
      for (int g = 0; g < updates; ++g) {
        ReplayBuffer::Sample batch = buffer_.sample(config_.batch_size, generator_);
        pipeline_.normalize(batch.observations.vector, batch.observations.vector);
        pipeline_.normalize(batch.next_observations.vector, batch.next_observations.vector);
        train(batch, ++updates_);
      }
    }
    update_seconds += std::chrono::duration<double>(Clock::now() - update_start).count();

    if (vector_steps_ % config_.report_every != 0 && steps_ < total_steps) continue;
    pipeline_.merge_statistics(sync_.get());
    TrainStats stats{.steps = steps_};
    for (const auto& [name, record] : records_) stats.losses[name] = record.first / record.second;
    records_.clear();
    stats.losses["learning_rate"] = config_.learning_rate;
    stats.losses["buffer_transitions"] = static_cast<double>(buffer_.size());
    stats.losses["updates"] = static_cast<double>(updates_);  // gradient steps so far
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

bool OffPolicyLearner::ready_to_train() {
  if (!distributed(sync_.get())) return buffer_.size() > config_.learning_starts;
  if (!ready_) {
    const double smallest = -agree_max(sync_.get(), -static_cast<double>(buffer_.size()));
    ready_ = smallest > static_cast<double>(config_.learning_starts);
  }
  return ready_;
}

std::uint64_t OffPolicyLearner::parameter_hash() const {
  std::vector<torch::Tensor> tensors;
  for (const auto& [key, module] : modules_) {
    for (const torch::Tensor& p : module->parameters()) tensors.push_back(p);
  }
  for (const auto& [key, tensor] : tensors_) tensors.push_back(*tensor);
  return tensor_hash(tensors);
}

void OffPolicyLearner::record(const std::string& name, double value) {
  auto& [sum, count] = records_[name];
  sum += value;
  ++count;
}

void OffPolicyLearner::act(const envs::ObservationBuffers& observation, std::span<double> action,
                           bool deterministic) {
  torch::NoGradGuard no_grad;
  pipeline_.process(observation, scratch_);
  unscale_actions(policy_action(scratch_, deterministic), env_.action_space(), action);
}

double OffPolicyLearner::value(const envs::ObservationBuffers& observation) {
  torch::NoGradGuard no_grad;
  pipeline_.process(observation, scratch_);
  const torch::Tensor v = state_value(scratch_);
  return v.defined() ? v[0].item<double>() : std::numeric_limits<double>::quiet_NaN();
}

// ---------------------------------------------------------------------------------------------
// Checkpoints: the registered parts, the normaliser, the generator and the counters. The
// replay buffer is not saved (it can take gigabytes): a resumed run refills it.

void OffPolicyLearner::checkpoint_module(std::string key, torch::nn::Module& module) {
  modules_.emplace_back(std::move(key), &module);
}

void OffPolicyLearner::checkpoint_optimizer(std::string key, torch::optim::Optimizer& optimizer) {
  optimizers_.emplace_back(std::move(key), &optimizer);
}

void OffPolicyLearner::checkpoint_tensor(std::string key, torch::Tensor& tensor) {
  tensors_.emplace_back(std::move(key), &tensor);
}

void OffPolicyLearner::save(const std::filesystem::path& file) const {
  const CheckpointInfo header{.algorithm = algorithm_, .config = text_, .steps = steps_};
  write_checkpoint(file, header, [&](torch::serialize::OutputArchive& archive) {
    for (const auto& [key, module] : modules_) write_module(archive, key, *module);
    for (const auto& [key, optimizer] : optimizers_) write_optimizer(archive, key, *optimizer);
    for (const auto& [key, tensor] : tensors_) archive.write(key, tensor->detach());
    write_normalizer(archive, "normalizer", pipeline_);
    write_generator(archive, "generator", generator_);
    archive.write("counters", torch::tensor({vector_steps_, updates_}, torch::kInt64));
  });
}

void OffPolicyLearner::load(const std::filesystem::path& file) {
  const CheckpointInfo info = read_checkpoint(
      file, algorithm_, [&](const CheckpointInfo& header, torch::serialize::InputArchive& archive) {
        observation_.check_matches(header.config);
        // Every module's and tensor's shape is checked before anything changes.
        std::vector<torch::Tensor> stored(tensors_.size());
        for (size_t i = 0; i < tensors_.size(); ++i) {
          archive.read(tensors_[i].first, stored[i]);
          if (stored[i].sizes() != tensors_[i].second->sizes()) {
            std::ostringstream message;
            message << tensors_[i].first << " has shape " << stored[i].sizes()
                    << " in the checkpoint, " << tensors_[i].second->sizes() << " here";
            throw UserError(message.str());
          }
        }
        std::vector<std::function<void()>> copies;
        for (const auto& [key, module] : modules_) {
          copies.push_back(stage_module(archive, key, *module));
        }
        for (const auto& copy : copies) copy();
        for (const auto& [key, optimizer] : optimizers_) read_optimizer(archive, key, *optimizer);
        torch::NoGradGuard no_grad;
        for (size_t i = 0; i < tensors_.size(); ++i) tensors_[i].second->copy_(stored[i]);
        read_normalizer(archive, "normalizer", pipeline_);
        read_generator(archive, "generator", generator_);
        torch::Tensor counters;
        archive.read("counters", counters);
        vector_steps_ = counters[0].item<long>();
        updates_ = counters[1].item<long>();
      });
  steps_ = info.steps;
  offset_generator(sync_.get(), generator_);
}

}  // namespace cradle::learn

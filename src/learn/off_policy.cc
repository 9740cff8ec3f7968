#include "learn/off_policy.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <exception>
#include <functional>
#include <limits>
#include <mutex>
#include <sstream>
#include <thread>
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
  table.add("overlap_collection", &overlap_collection,
            "collect on a thread of its own during the updates (stale actor; not bitwise "
            "reproducible)");
  table.add("actor_refresh", &actor_refresh,
            "overlap_collection: gradient steps between refreshes of the collector's actor");
}

void OffPolicyConfig::check(std::string_view algorithm) const {
  const std::string name(algorithm);
  if (batch_size < 1 || train_freq < 1 || gradient_steps < 1 || report_every < 1) {
    throw UserError(name +
                    ": batch_size, train_freq, gradient_steps and report_every must be positive");
  }
  if (learning_starts < 0) throw UserError(name + ": learning_starts must be >= 0");
  if (actor_refresh < 1) throw UserError(name + ": actor_refresh must be positive");
  if (episode_train_freq < 0) throw UserError(name + ": episode_train_freq must be >= 0");
  if (!(tau > 0 && tau <= 1)) throw UserError(name + ": tau must be in (0, 1]");
  if (!(gamma >= 0 && gamma <= 1)) throw UserError(name + ": gamma must be in [0, 1]");
  if (!(learning_rate > 0)) throw UserError(name + ": learning_rate must be positive");
}

void OffPolicyNetworkConfig::check(std::string_view algorithm) const {
  // The actor's output heads and the critics' last layer sit on the last hidden layer.
  if (pi_layers.empty() || qf_layers.empty())
    throw UserError(std::string(algorithm) + ": pi_layers and qf_layers need at least one hidden " +
                    "layer (e.g. 256,256); got " + (pi_layers.empty() ? "pi_layers" : "qf_layers") +
                    " empty");
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
                       const OffPolicyNetworkConfig& config, at::Generator& generator)
    : critics_(critics), relu_(config.activation == "relu") {
  if (config.activation != "tanh" && config.activation != "relu") {
    throw UserError("activation '" + config.activation + "': expected tanh or relu");
  }
  encoder_ = register_module("encoder", MultiInputEncoder(shape, config.cnn_features));
  // SB3 keeps PyTorch's default initialisation for off-policy networks.
  init_layers(*encoder_, 1.0, /*orthogonal=*/false, generator);
  std::vector<int> sizes{encoder_->output_size() + action_size};
  for (const int size : config.qf_layers) {
    if (size <= 0) throw UserError("hidden layer sizes must be positive");
    sizes.push_back(size);
  }
  sizes.push_back(1);
  double parameters = 0;
  for (size_t l = 0; l + 1 < sizes.size(); ++l)
    parameters += critics * (static_cast<double>(sizes[l]) + 1) * sizes[l + 1];
  check_network_memory(std::to_string(critics) + " critics (qf_layers)", parameters);
  for (size_t l = 0; l + 1 < sizes.size(); ++l) {
    const std::string name = std::to_string(l);
    weights_.push_back(
        register_parameter("weight" + name, torch::empty({critics, sizes[l], sizes[l + 1]})));
    biases_.push_back(register_parameter("bias" + name, torch::empty({critics, 1, sizes[l + 1]})));
  }
  // Uniform in +-1/sqrt(fan_in), critic by critic and layer by layer, weight then bias: the
  // draws (and values) of n separate MLPs of Linear layers.
  torch::NoGradGuard no_grad;
  for (int i = 0; i < critics; ++i) {
    for (size_t l = 0; l < weights_.size(); ++l) {
      const double bound = 1.0 / std::sqrt(static_cast<double>(sizes[l]));
      weights_[l][i].copy_(
          torch::empty({sizes[l + 1], sizes[l]}).uniform_(-bound, bound, generator).t());
      biases_[l][i][0].uniform_(-bound, bound, generator);
    }
  }
}

torch::Tensor CriticImpl::activate(const torch::Tensor& x) const {
  return relu_ ? torch::relu(x) : torch::tanh(x);
}

torch::Tensor CriticImpl::forward(const ObsBatch& observation, const torch::Tensor& actions) {
  const torch::Tensor features = encoder_->forward(observation);
  // Every critic reads the same input: broadcast over the critics, not copied.
  const auto broadcast = [this](const torch::Tensor& x) {
    return x.unsqueeze(0).expand({critics_, x.size(0), x.size(1)});
  };
  // The first layer on [features, actions] as its two row blocks of weights, so that a gradient
  // wanted for the actions only (the actor's loss, critics frozen) is not computed for the
  // features too.
  const int64_t f = features.size(1);
  torch::Tensor h = torch::baddbmm(biases_[0], broadcast(features), weights_[0].narrow(1, 0, f));
  h = torch::baddbmm(h, broadcast(actions), weights_[0].narrow(1, f, actions.size(1)));
  for (size_t l = 1; l < weights_.size(); ++l) {
    h = torch::baddbmm(biases_[l], activate(h), weights_[l]);
  }
  return h.squeeze(2);
}

torch::Tensor CriticImpl::q1(const ObsBatch& observation, const torch::Tensor& actions) {
  const torch::Tensor features = encoder_->forward(observation);
  // The first layer in two row blocks, as in forward().
  const int64_t f = features.size(1);
  torch::Tensor h = torch::addmm(biases_[0][0], features, weights_[0][0].narrow(0, 0, f));
  h = torch::addmm(h, actions, weights_[0][0].narrow(0, f, actions.size(1)));
  for (size_t l = 1; l < weights_.size(); ++l) {
    h = torch::addmm(biases_[l][0], activate(h), weights_[l][0]);
  }
  return h.squeeze(1);
}

void check_critic_format(torch::serialize::InputArchive& archive, const std::string& key) {
  torch::serialize::InputArchive critic, legacy;
  if (!archive.try_read(key, critic) || !critic.try_read("q1", legacy)) return;
  throw UserError(key +
                  " is in the format of separate critic MLPs (q1, q2, ...; Cradle before "
                  "the fused critics), this build reads fused critics (weight<l> [n, in, out]): "
                  "retrain, or load it with an older build");
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
  if (config_.overlap_collection) {
    learn_overlapped(total_steps, on_progress);
    return;
  }
  const Clock::time_point start = Clock::now();
  const long start_steps = steps_;
  const int envs = env_.num_envs();
  collector_.start(draw_env_seed(generator_));
  torch::Tensor random = torch::zeros({envs, action_size()}, torch::kFloat32);
  records_.clear();
  double collect_seconds = 0, update_seconds = 0;  // since the last report
  std::vector<long> episode_length(envs, 0);       // episode_train_freq: steps per env
  std::vector<std::uint8_t> episode_ended(envs, 0);
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
      // Every update is a collective: the ranks' episodes end apart, so at each step they agree
      // on the most updates any rank's ended episodes ask for.
      if (distributed(sync_.get()))
        updates = static_cast<int>(agree_max(sync_.get(), static_cast<double>(updates)));
    }
    if (updates > 0 && ready_to_train()) run_updates(updates, pipeline_.normalizer());
    update_seconds += std::chrono::duration<double>(Clock::now() - update_start).count();

    if (vector_steps_ % config_.report_every != 0 && steps_ < total_steps) continue;
    const TrainStats stats = report(start, start_steps, collect_seconds, update_seconds);
    if (on_progress && !on_progress(stats)) break;
  }
}

TrainStats OffPolicyLearner::report(Clock::time_point start, long start_steps,
                                    double& collect_seconds, double& update_seconds) {
  pipeline_.merge_statistics(sync_.get());
  TrainStats stats{.steps = steps_};
  for (const auto& [name, record] : records_) stats.losses[name] = record.first / record.second;
  records_.clear();
  stats.losses["learning_rate"] = config_.learning_rate;
  stats.losses["buffer_transitions"] = static_cast<double>(buffer_.size());
  stats.losses["updates"] = static_cast<double>(updates_);  // gradient steps so far
  stats.losses["collect_seconds"] = std::exchange(collect_seconds, 0.0);
  stats.losses["update_seconds"] = std::exchange(update_seconds, 0.0);
  collector_.episodes().report_into(stats);
  const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
  stats.sps = static_cast<double>(steps_ - start_steps) / std::max(seconds, 1e-9);
  return stats;
}

OffPolicyLearner::ActorCopy OffPolicyLearner::copy_actor() {
  throw UserError(algorithm_ + ": overlap_collection is not available for this algorithm");
}

void OffPolicyLearner::learn_overlapped(long total_steps, const ProgressFn& on_progress) {
  if (config_.episode_train_freq > 0 || distributed(sync_.get()) || !shape().images.empty()) {
    throw UserError(algorithm_ +
                    ": overlap_collection needs train_freq/gradient_steps (not "
                    "episode_train_freq), one process (not --distributed) and vector "
                    "observations (image updates use every core already)");
  }
  if (steps_ >= total_steps) return;
  const Clock::time_point start = Clock::now();
  const long start_steps = steps_;
  const int envs = env_.num_envs();
  collector_.start(draw_env_seed(generator_));
  // The collector's own generator and actor copy, and its staging buffer (one cycle).
  at::Generator collect_generator =
      at::make_generator<at::CPUGeneratorImpl>(draw_env_seed(generator_));
  const ActorCopy actor = copy_actor();
  const std::vector<torch::Tensor> source = actor.source->parameters();
  const std::vector<torch::Tensor> copy = actor.copy->parameters();
  auto refresh = [&] {
    torch::NoGradGuard no_grad;
    for (size_t i = 0; i < copy.size(); ++i) copy[i].copy_(source[i]);
  };
  refresh();
  ReplayBuffer staging(static_cast<long>(config_.train_freq) * envs, shape(), action_size());
  records_.clear();
  double collect_seconds = 0, update_seconds = 0;  // since the last report

  // The handoff: the learner orders `order` vector steps (from env step `first`); the collector
  // sets order back to 0 when they are staged (or it failed, or was told to stop).
  struct Handoff {
    std::mutex mutex;
    std::condition_variable changed;
    long order = 0, first = 0;
    bool stop = false;
    std::exception_ptr error;
    double seconds = 0;  // the collector's time of the last order
  } handoff;
  // The collector computes with the learner thread's LibTorch thread count (torch_threads): a new
  // thread starts at OpenMP's default, every core, and a different split of an operation may
  // round differently, so the run would depend on the machine's core count.
  const int torch_threads = torch::get_num_threads();
  auto collect = [&] {
    const ScopedTorchThreads same_threads(torch_threads);
    std::unique_lock lock(handoff.mutex);
    while (true) {
      handoff.changed.wait(lock, [&] { return handoff.order > 0 || handoff.stop; });
      if (handoff.stop) return;
      const long order = handoff.order, first = handoff.first;
      lock.unlock();
      // Everything below is the collector's until it sets order back to 0.
      const Clock::time_point begin = Clock::now();
      std::exception_ptr error;
      try {
        torch::Tensor random = torch::zeros({envs, action_size()}, torch::kFloat32);
        for (long k = 0; k < order; ++k) {
          torch::Tensor actions;
          if (first + k * envs < config_.learning_starts) {
            actions = random.uniform_(-1.0, 1.0, collect_generator);
          } else {
            torch::NoGradGuard no_grad;
            actions = actor.explore(collector_.observation(), collect_generator);
          }
          collector_.step(actions, staging);
        }
      } catch (...) {
        error = std::current_exception();
      }
      lock.lock();
      handoff.seconds = std::chrono::duration<double>(Clock::now() - begin).count();
      handoff.error = error;
      handoff.order = 0;
      handoff.changed.notify_all();
      if (error) return;
    }
  };
  std::thread collector(collect);
  // Stops and joins the collector however learn() ends (returns, throws).
  struct Join {
    Handoff& handoff;
    std::thread& thread;
    ~Join() {
      {
        const std::lock_guard lock(handoff.mutex);
        handoff.stop = true;
      }
      handoff.changed.notify_all();
      thread.join();
    }
  } join{handoff, collector};
  auto launch = [&](long vector_steps) {
    const std::lock_guard lock(handoff.mutex);
    handoff.order = vector_steps;
    handoff.first = steps_;
    handoff.changed.notify_all();
  };
  // Waits for the collector to finish its order; returns the vector steps it staged.
  long ordered = 0;
  auto wait = [&] {
    std::unique_lock lock(handoff.mutex);
    handoff.changed.wait(lock, [&] { return handoff.order == 0; });
    if (handoff.error) std::rethrow_exception(handoff.error);
    collect_seconds += std::exchange(handoff.seconds, 0.0);
    return std::exchange(ordered, 0L);
  };
  auto order = [&] {
    const long left = (total_steps - steps_ + envs - 1) / envs;
    ordered = std::min<long>(config_.train_freq, left);
    if (ordered > 0) launch(ordered);
  };

  order();
  long refreshed = updates_;  // updates_ at the last refresh
  RunningMeanStd statistics;  // the normaliser's at the handoff, for the learner's minibatches
  bool report_due = false;    // by the transitions merged at the last handoff
  while (true) {
    // Handoff: the collector is idle and the last merge's updates are done. Report those (the
    // synchronous loop's reports, at the same steps), then merge and count the staged ones.
    const long staged = wait();
    if (report_due || steps_ >= total_steps) {
      const TrainStats stats = report(start, start_steps, collect_seconds, update_seconds);
      if (on_progress && !on_progress(stats)) break;
      if (steps_ >= total_steps) break;
    }
    buffer_.append(staging);
    int updates = 0;
    report_due = false;
    for (long k = 0; k < staged; ++k) {
      steps_ += envs;
      ++vector_steps_;
      if (vector_steps_ % config_.train_freq == 0) updates += config_.gradient_steps;
      if (vector_steps_ % config_.report_every == 0) report_due = true;
    }
    if (updates_ - refreshed >= config_.actor_refresh) {
      refresh();
      refreshed = updates_;
    }
    statistics = pipeline_.normalizer();
    order();

    // The merged transitions' gradient steps, while the collector collects the next ones.
    const Clock::time_point update_start = Clock::now();
    if (updates > 0 && ready_to_train()) run_updates(updates, statistics);
    update_seconds += std::chrono::duration<double>(Clock::now() - update_start).count();
  }
}

void OffPolicyLearner::run_updates(int count, const RunningMeanStd& statistics) {
  const ScopedTorchThreads threads(update_threads_);
  for (int g = 0; g < count; ++g) {
    ReplayBuffer::Sample batch = buffer_.sample(config_.batch_size, generator_);
    pipeline_.normalize(batch.observations.vector, batch.observations.vector, statistics);
    pipeline_.normalize(batch.next_observations.vector, batch.next_observations.vector, statistics);
    train(batch, ++updates_);
  }
}

void OffPolicyLearner::update(int count) {
  if (buffer_.size() == 0) throw UserError(algorithm_ + ": no transitions to update on yet");
  run_updates(count, pipeline_.normalizer());
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
          if (module->as<CriticImpl>() != nullptr) check_critic_format(archive, key);
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

#include "learn/rollout.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>

#include "core/error.h"

namespace cradle::learn {

void compute_gae(int steps, int envs, std::span<const float> rewards, std::span<const float> values,
                 std::span<const float> last_values, std::span<const std::uint8_t> terminated,
                 std::span<const std::uint8_t> dones, double gamma, double gae_lambda,
                 std::span<float> advantages, std::span<float> returns) {
  for (int e = 0; e < envs; ++e) {
    double next_advantage = 0;
    for (int t = steps - 1; t >= 0; --t) {
      const int row = t * envs + e;
      const double next_value = t + 1 < steps ? values[row + envs] : last_values[e];
      const double bootstrap = terminated[row] ? 0.0 : gamma * next_value;
      const double delta = rewards[row] + bootstrap - values[row];
      const double carry = dones[row] ? 0.0 : gamma * gae_lambda * next_advantage;
      next_advantage = delta + carry;
      advantages[row] = static_cast<float>(next_advantage);
      returns[row] = static_cast<float>(next_advantage + values[row]);
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Buffer

RolloutBuffer::RolloutBuffer(int steps, int envs, const ObsShape& shape, int action_size)
    : steps(steps), envs(envs) {
  const long n = static_cast<long>(steps) * envs;
  observations = ObsBatch::zeros(shape, n);
  actions = torch::zeros({n, action_size}, torch::kFloat32);
  log_probs = torch::zeros({n}, torch::kFloat32);
  values = torch::zeros({n}, torch::kFloat32);
  rewards = torch::zeros({n}, torch::kFloat32);
  terminated = torch::zeros({n}, torch::kUInt8);
  dones = torch::zeros({n}, torch::kUInt8);
  valid = torch::zeros({n}, torch::kUInt8);
  last_values = torch::zeros({envs}, torch::kFloat32);
  advantages = torch::zeros({n}, torch::kFloat32);
  returns = torch::zeros({n}, torch::kFloat32);
}

void RolloutBuffer::compute_returns_and_advantages(double gamma, double gae_lambda) {
  const size_t n = rows();
  auto floats = [](const torch::Tensor& t) {
    return std::span<float>(t.data_ptr<float>(), static_cast<size_t>(t.numel()));
  };
  auto bytes = [n](const torch::Tensor& t) {
    return std::span<const std::uint8_t>(t.data_ptr<std::uint8_t>(), n);
  };
  compute_gae(steps, envs, floats(rewards), floats(values), floats(last_values), bytes(terminated),
              bytes(dones), gamma, gae_lambda, floats(advantages), floats(returns));
}

torch::Tensor RolloutBuffer::valid_rows() const { return torch::nonzero(valid).squeeze(1); }

// ---------------------------------------------------------------------------------------------
// Episode statistics

void EpisodeStats::reset(int envs) {
  returns_.assign(envs, 0.0);
  lengths_.assign(envs, 0);
  sum_return_ = sum_length_ = 0;
  ended_ = 0;
}

void EpisodeStats::add(int env, double reward) {
  returns_[env] += reward;
  ++lengths_[env];
}

void EpisodeStats::end(int env) {
  sum_return_ += returns_[env];
  sum_length_ += lengths_[env];
  ++ended_;
  returns_[env] = 0;
  lengths_[env] = 0;
}

void EpisodeStats::report_into(TrainStats& stats) {
  const double none = std::numeric_limits<double>::quiet_NaN();
  stats.episodes = ended_;
  stats.episodic_return = ended_ > 0 ? sum_return_ / ended_ : none;
  stats.episodic_length = ended_ > 0 ? sum_length_ / ended_ : none;
  sum_return_ = sum_length_ = 0;
  ended_ = 0;
}

// ---------------------------------------------------------------------------------------------
// Collection

void clip_actions(const torch::Tensor& samples, const Box& bounds, std::span<double> actions) {
  const torch::Tensor contiguous = samples.contiguous();
  const float* src = contiguous.data_ptr<float>();
  const size_t size = bounds.low.size();
  for (size_t k = 0; k < actions.size(); ++k) {
    const size_t j = k % size;
    actions[k] = std::clamp(static_cast<double>(src[k]), bounds.low[j], bounds.high[j]);
  }
}

EnvStepper::EnvStepper(VecEnv& env, RewardHook reward_hook)
    : env_(env), reward_hook_(std::move(reward_hook)) {
  rewards_.resize(env.num_envs());
  pending_.assign(env.num_envs(), 0);
  real_.assign(env.num_envs(), 0);
}

void EnvStepper::start(std::uint64_t seed) {
  env_.reset(seed);
  pending_.assign(env_.num_envs(), 0);
  episodes_.reset(env_.num_envs());
}

void EnvStepper::step(std::span<const double> actions) {
  env_.step(actions);
  const std::span<const double> env_rewards = env_.rewards();
  std::copy(env_rewards.begin(), env_rewards.end(), rewards_.begin());
  if (reward_hook_) reward_hook_(env_, actions, rewards_);

  // An env that this step autoreset has no (s, a, r, s'); the others extend their episodes.
  const std::span<const std::uint8_t> terminated = env_.terminated();
  const std::span<const std::uint8_t> truncated = env_.truncated();
  for (int e = 0; e < env_.num_envs(); ++e) {
    real_[e] = !pending_[e];
    if (pending_[e]) {
      pending_[e] = 0;
      continue;
    }
    episodes_.add(e, rewards_[e]);
    if (terminated[e] || truncated[e]) {
      episodes_.end(e);
      pending_[e] = 1;
    }
  }
}

RolloutCollector::RolloutCollector(VecEnv& env, ObservationPipeline& pipeline,
                                   RewardHook reward_hook)
    : env_(env),
      pipeline_(pipeline),
      stepper_(env, reward_hook),
      async_(dynamic_cast<AsyncVecEnv*>(&env)) {
  const int envs = env.num_envs();
  const int action_size = env.action_space().size();
  observation_ = ObsBatch::zeros(pipeline.shape(), envs);
  noise_ = torch::zeros({envs, action_size}, torch::kFloat32);
  actions_.resize(static_cast<size_t>(envs) * action_size);
  if (!async_) return;
  reward_hook_ = std::move(reward_hook);
  sent_actions_.resize(static_cast<size_t>(envs) * action_size);
  hook_actions_.resize(static_cast<size_t>(async_->batch_size()) * action_size);
  hook_rewards_.resize(async_->batch_size());
  all_ids_.resize(envs);
  for (int e = 0; e < envs; ++e) all_ids_[e] = e;
  filled_.assign(envs, 0);
  pending_.assign(envs, 0);
  batch_observation_ = ObsBatch::zeros(pipeline.shape(), async_->batch_size());
  batch_noise_ = torch::zeros({async_->batch_size(), action_size}, torch::kFloat32);
  send_ids_.reserve(async_->batch_size());
  send_actions_.reserve(static_cast<size_t>(async_->batch_size()) * action_size);
}

void RolloutCollector::start(std::uint64_t seed) {
  stepper_.start(seed);
  pipeline_.process(env_, /*update_stats=*/true, observation_);
  std::fill(pending_.begin(), pending_.end(), 0);
}

namespace {

// Copies row `from_row` of `from` into row `to_row` of `to` (same shapes, contiguous).
void copy_row(const ObsBatch& from, long from_row, ObsBatch& to, long to_row) {
  const long n = from.vector.size(1);
  std::memcpy(to.vector.data_ptr<float>() + to_row * n,
              from.vector.data_ptr<float>() + from_row * n, sizeof(float) * n);
  for (size_t k = 0; k < from.images.size(); ++k) {
    const long bytes = from.images[k].numel() / from.images[k].size(0);
    std::memcpy(to.images[k].data_ptr<std::uint8_t>() + to_row * bytes,
                from.images[k].data_ptr<std::uint8_t>() + from_row * bytes, bytes);
  }
}

}  // namespace

void RolloutCollector::collect(GaussianActorCritic& policy, at::Generator& generator,
                               RolloutBuffer& buffer) {
  if (async_) return collect_async(policy, generator, buffer);
  // Inference mode, not only no-grad: the policy's forward passes skip autograd's bookkeeping
  // (version counters, view tracking), a share of a small policy's cost per step (PPO self-touch
  // collects ~5 % faster); the kernels, and so the numbers, are the same. Only in-place writes
  // reach tensors that live on (the buffer, the noise, the observation batches).
  const c10::InferenceMode inference;
  const int envs = env_.num_envs();
  const long action_size = buffer.actions.size(1);
  const double half_log_2pi = 0.5 * std::log(2.0 * std::numbers::pi);
  for (int t = 0; t < buffer.steps; ++t) {
    const long row = static_cast<long>(t) * envs;
    buffer.observations.assign(row, observation_);

    // a = mu + sigma * eps, eps ~ N(0, I); log pi(a) = sum(-eps^2 / 2 - log sigma - log(2 pi) / 2).
    const GaussianActorCriticImpl::Output out = policy->forward(observation_);
    noise_.normal_(0.0, 1.0, generator);
    const torch::Tensor actions = out.mean + torch::exp(policy->log_std()) * noise_;
    const torch::Tensor log_probs =
        (-0.5 * noise_.square() - policy->log_std() - half_log_2pi).sum(1);
    std::memcpy(buffer.actions.data_ptr<float>() + row * action_size, actions.data_ptr<float>(),
                sizeof(float) * envs * action_size);
    std::memcpy(buffer.log_probs.data_ptr<float>() + row, log_probs.data_ptr<float>(),
                sizeof(float) * envs);
    std::memcpy(buffer.values.data_ptr<float>() + row, out.value.contiguous().data_ptr<float>(),
                sizeof(float) * envs);

    clip_actions(actions, env_.action_space(), actions_);
    stepper_.step(actions_);

    const std::span<const std::uint8_t> terminated = env_.terminated();
    const std::span<const std::uint8_t> truncated = env_.truncated();
    const std::span<const std::uint8_t> real = stepper_.real();
    float* rewards = buffer.rewards.data_ptr<float>() + row;
    std::uint8_t* terminal = buffer.terminated.data_ptr<std::uint8_t>() + row;
    std::uint8_t* done = buffer.dones.data_ptr<std::uint8_t>() + row;
    std::uint8_t* valid = buffer.valid.data_ptr<std::uint8_t>() + row;
    for (int e = 0; e < envs; ++e) {
      valid[e] = real[e];
      rewards[e] = real[e] ? static_cast<float>(stepper_.rewards()[e]) : 0.0f;
      terminal[e] = real[e] && terminated[e];
      done[e] = real[e] && (terminated[e] || truncated[e]);
    }
    pipeline_.process(env_, /*update_stats=*/true, observation_);
  }
  buffer.last_values.copy_(policy->value(observation_));
}

void RolloutCollector::collect_async(GaussianActorCritic& policy, at::Generator& generator,
                                     RolloutBuffer& buffer) {
  const c10::InferenceMode inference;  // as collect()
  AsyncVecEnv& vec = *async_;
  const int envs = vec.num_envs();
  const long action_size = buffer.actions.size(1);
  const Box& bounds = vec.action_space();
  const double half_log_2pi = 0.5 * std::log(2.0 * std::numbers::pi);
  float* actions_out = buffer.actions.data_ptr<float>();
  float* log_probs_out = buffer.log_probs.data_ptr<float>();
  float* values_out = buffer.values.data_ptr<float>();
  float* rewards_out = buffer.rewards.data_ptr<float>();
  std::uint8_t* terminal_out = buffer.terminated.data_ptr<std::uint8_t>();
  std::uint8_t* done_out = buffer.dones.data_ptr<std::uint8_t>();
  std::uint8_t* valid_out = buffer.valid.data_ptr<std::uint8_t>();
  float* last_values_out = buffer.last_values.data_ptr<float>();
  EpisodeStats& episodes = stepper_.episodes();

  // Every env is held: the first row of each, as one lock-step batch (rows 0..envs-1), sent.
  {
    buffer.observations.assign(0, observation_);
    const GaussianActorCriticImpl::Output out = policy->forward(observation_);
    noise_.normal_(0.0, 1.0, generator);
    const torch::Tensor actions = out.mean + torch::exp(policy->log_std()) * noise_;
    const torch::Tensor log_probs =
        (-0.5 * noise_.square() - policy->log_std() - half_log_2pi).sum(1);
    std::memcpy(actions_out, actions.data_ptr<float>(), sizeof(float) * envs * action_size);
    std::memcpy(log_probs_out, log_probs.data_ptr<float>(), sizeof(float) * envs);
    std::memcpy(values_out, out.value.contiguous().data_ptr<float>(), sizeof(float) * envs);
    clip_actions(actions, bounds, actions_);
    std::copy(actions_.begin(), actions_.end(), sent_actions_.begin());
    std::fill(filled_.begin(), filled_.end(), 1);
    vec.send(actions_, all_ids_);
  }

  // Then batches as they come: record each env's last transition, and act again until the env
  // has filled its rows; a full env's value is its bootstrap value and it waits, held.
  int full = 0;
  while (full < envs) {
    const AsyncVecEnv::Batch batch = vec.recv();
    const int k = batch.size();
    const BatchView view(vec, batch);
    // The rewards to train on: the env's plus the hook's, which sees the batch as a vector.
    std::copy(batch.rewards.begin(), batch.rewards.end(), hook_rewards_.begin());
    if (reward_hook_) {
      for (int j = 0; j < k; ++j) {
        std::copy_n(sent_actions_.data() + static_cast<size_t>(batch.ids[j]) * action_size,
                    action_size, hook_actions_.data() + static_cast<size_t>(j) * action_size);
      }
      reward_hook_(view, std::span(hook_actions_).first(static_cast<size_t>(k) * action_size),
                   std::span(hook_rewards_).first(k));
    }
    for (int j = 0; j < k; ++j) {
      const int e = batch.ids[j];
      const long row = static_cast<long>(filled_[e] - 1) * envs + e;
      // An autoreset step is no transition (next-step autoreset, as EnvStepper tells).
      const bool real = !pending_[e];
      const bool ended = batch.terminated[j] || batch.truncated[j];
      pending_[e] = real && ended;
      if (real) {
        episodes.add(e, hook_rewards_[j]);
        if (ended) episodes.end(e);
      }
      valid_out[row] = real;
      rewards_out[row] = real ? static_cast<float>(hook_rewards_[j]) : 0.0f;
      terminal_out[row] = real && batch.terminated[j];
      done_out[row] = real && ended;
    }
    pipeline_.process(view, /*update_stats=*/true, batch_observation_);
    const ObsBatch observation =
        k == batch_observation_.rows() ? batch_observation_ : batch_observation_.slice(0, k);
    const GaussianActorCriticImpl::Output out = policy->forward(observation);
    const torch::Tensor noise = batch_noise_.slice(0, 0, k);
    noise.normal_(0.0, 1.0, generator);
    const torch::Tensor actions = (out.mean + torch::exp(policy->log_std()) * noise).contiguous();
    const torch::Tensor log_probs =
        (-0.5 * noise.square() - policy->log_std() - half_log_2pi).sum(1).contiguous();
    const torch::Tensor values = out.value.contiguous();
    const float* action = actions.data_ptr<float>();
    send_ids_.clear();
    send_actions_.clear();
    for (int j = 0; j < k; ++j) {
      const int e = batch.ids[j];
      copy_row(batch_observation_, j, observation_, e);
      if (filled_[e] == buffer.steps) {
        last_values_out[e] = values.data_ptr<float>()[j];
        ++full;
        continue;
      }
      const long row = static_cast<long>(filled_[e]++) * envs + e;
      copy_row(batch_observation_, j, buffer.observations, row);
      std::memcpy(actions_out + row * action_size, action + j * action_size,
                  sizeof(float) * action_size);
      log_probs_out[row] = log_probs.data_ptr<float>()[j];
      values_out[row] = values.data_ptr<float>()[j];
      for (long d = 0; d < action_size; ++d) {
        const double clipped = std::clamp(static_cast<double>(action[j * action_size + d]),
                                          bounds.low[d], bounds.high[d]);
        sent_actions_[e * action_size + d] = clipped;
        send_actions_.push_back(clipped);
      }
      send_ids_.push_back(e);
    }
    if (!send_ids_.empty()) vec.send(send_actions_, send_ids_);
  }
}

void act_gaussian(ObservationPipeline& pipeline, GaussianActorCritic& policy,
                  at::Generator& generator, const Box& bounds,
                  const envs::ObservationBuffers& observation, ObsBatch& scratch,
                  std::span<double> action, bool deterministic) {
  torch::NoGradGuard no_grad;
  pipeline.process(observation, scratch);
  const GaussianActorCriticImpl::Output out = policy->forward(scratch);
  torch::Tensor sample = out.mean;
  if (!deterministic) {
    sample = out.mean + torch::exp(policy->log_std()) *
                            torch::randn(out.mean.sizes(), generator, torch::kFloat32);
  }
  clip_actions(sample, bounds, action);
}

}  // namespace cradle::learn

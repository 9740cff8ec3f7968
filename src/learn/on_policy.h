// What PPO and A2C share (SB3's OnPolicyAlgorithm): the settings parse, the networks, the rollout
// collector, GAE, the learning-rate schedule, the progress report, acting and checkpoints. Each
// algorithm's file holds its optimiser and its update, the part the papers are about. The whole
// loop is in this one header, so that PPO reads top to bottom in ppo.h, ppo.cc and this file
// (the collector and GAE behind it are rollout.h's, shared with the off-policy learners).
//
// The loop:
//   for each iteration until the step budget is spent:
//     (optionally) anneal the learning rate linearly to 0
//     collect n_steps x num_envs transitions with the current Gaussian policy
//     compute advantages A and value targets R by GAE(gamma, lambda)
//     the algorithm's update on the rollout
//     every report_every iterations (and at the end): report the updates' mean losses, the
//     episodes that ended and the speed
//
// With overlap_update (off by default) rollout k+1 is collected on a thread of its own while the
// update of rollout k runs (learn_overlapped, on_policy.cc), in two rollout buffers in turn:
//   collect rollout 0 with the actor copy (= the initial policy)
//   for k = 0, 1, ...:  (boundary k: nothing runs; the policy holds every update before k)
//     budget spent: the update on rollout k, report, return
//     every report_every rollouts: report (steps and episodes through rollout k, the losses of
//       the updates since the last report); it says stop: the update on rollout k, return
//     copy the policy's parameters into the actor copy
//     collector thread: rollout k+1 with the copy (its own generator, LibTorch at
//       torch_threads) into the other buffer; meanwhile this thread: the update on rollout k (at
//       update_threads); wait for both
// So collection k+1 always acts with the parameters after update k-1: one update of policy lag,
// fixed whatever thread finishes first (PPO's ratio divides by the log-probabilities recorded at
// collection, an importance ratio that stays right under the lag, as APPO/IMPALA's lag-1). Only
// the collector touches the envs, the collector and the statistics (observation, return), and
// only the update the policy, optimiser and learner generator, so a run is bitwise repeatable
// for a seed and env count. An iteration takes max(collect, update) instead of their sum.
// Reports come at the same steps as the synchronous loop's, before the rollout's update: their
// losses are the previous update's (the first report of a learn() call has none, and the update
// that follows a report saying stop is in none); the one at the end of the budget has its own.
// learn() returns with no rollout in flight and every collected rollout trained on, at the step
// the synchronous loop would: checkpoints and --resume are as exact as without overlap.
#pragma once

#include <torch/torch.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <utility>

#include "core/error.h"
#include "learn/checkpoint.h"
#include "learn/grad_tensors.h"
#include "learn/hyperparams.h"
#include "learn/learner.h"
#include "learn/networks.h"
#include "learn/preprocess.h"
#include "learn/return_normalizer.h"
#include "learn/rollout.h"

namespace cradle::learn {

// The loop's settings, from the algorithm's config.
struct OnPolicyLoop {
  double learning_rate = 3e-4;
  bool anneal_lr = false;  // decay the learning rate linearly to 0 over learn()'s total_steps
  int n_steps = 2048;      // vector steps per env per rollout
  double gamma = 0.99, gae_lambda = 0.95;
  long report_every = 1;  // rollouts (and updates) per progress report
  // Rewards scaled by the return normaliser (learn/return_normalizer.h), after the reward hook.
  bool normalize_returns = false;
  // Collect the next rollout while updating on this one (learn_overlapped, see the top).
  bool overlap_update = false;
};

// Every setting of an on-policy learner: the algorithm's own (`Own`, with a bind(table)), the
// loop's (taken from it), the observation's and the policy network's.
template <typename Own>
struct OnPolicySettings {
  Own own;
  OnPolicyLoop loop;
  ObservationConfig observation;
  PolicyConfig policy;
  std::string text;  // every value, "name = value" lines
};

// Binds every setting, applies the overrides strictly (UserError for an unknown name or a bad
// value) and copies the loop's settings, which every `Own` holds under the same names; the
// algorithm checks its own values after and sets the loop's others.
template <typename Own>
OnPolicySettings<Own> parse_on_policy_settings(const LearnerOptions& options) {
  apply_torch_options(options);
  OnPolicySettings<Own> settings;
  Hyperparameters table;
  settings.own.bind(table);
  settings.observation.bind(table);
  settings.policy.bind(table);
  table.apply(options.hyperparameters);
  settings.text = table.to_text();
  const Own& own = settings.own;
  settings.loop.learning_rate = own.learning_rate;
  settings.loop.anneal_lr = own.anneal_lr;
  settings.loop.n_steps = own.n_steps;
  settings.loop.gamma = own.gamma;
  settings.loop.gae_lambda = own.gae_lambda;
  settings.loop.overlap_update = own.overlap_update;
  return settings;
}

// Standardised advantages: (A - mean) / (std + 1e-8).
inline torch::Tensor standardize(const torch::Tensor& advantages) {
  return (advantages - advantages.mean()) / (advantages.std() + 1e-8);
}

// The return normaliser of loop.normalize_returns (null when off). UserError for an async vector
// env (its hook sees batches, not fixed env indices) or a data-parallel run (each rank would
// scale by its own statistics).
std::unique_ptr<ReturnNormalizer> make_return_normalizer(const OnPolicyLoop& loop,
                                                         const VecEnv& env,
                                                         const LearnerOptions& options);
// `first` (may be empty), then the normaliser's scaling (when given), as one hook.
RewardHook chain_reward_hooks(RewardHook first, ReturnNormalizer* returns);
// UserError unless a checkpoint's config text says normalize_returns = `wanted` (a checkpoint of
// an earlier build, without the key, holds no return statistics).
void check_saved_normalize_returns(const std::string& config, bool wanted);
// The statistics as a checkpoint entry "return_normalizer" (mean, var, count as float64).
void write_return_statistics(torch::serialize::OutputArchive& archive,
                             const ReturnNormalizer& returns);
// Reads them back; UserError when the checkpoint has none or they are malformed.
ReturnStatistics read_return_statistics(torch::serialize::InputArchive& archive);

// The learner skeleton. An algorithm builds its optimiser on parameters() in its constructor,
// hands it to use_optimizer(), and implements update().
class OnPolicyLearner : public Learner {
 public:
  std::string_view algorithm() const override { return algorithm_; }
  long steps() const override { return steps_; }
  std::string config_text() const override { return text_; }

  void learn(long total_steps, const ProgressFn& on_progress) override {
    if (loop_.overlap_update) return learn_overlapped(total_steps, on_progress);
    using Clock = std::chrono::steady_clock;
    const auto seconds = [](Clock::time_point from, Clock::time_point to) {
      return std::chrono::duration<double>(to - from).count();
    };
    const Clock::time_point start = Clock::now();
    const long start_steps = steps_;
    collector_.start(draw_env_seed(generator_));
    if (returns_) returns_->start();
    long iteration = 0;
    std::map<std::string, double> sums;              // of the updates since the last report
    double collect_seconds = 0, update_seconds = 0;  // since the last report
    while (steps_ < total_steps) {
      // Learning rate for this iteration: constant, or annealed linearly to 0.
      double learning_rate = loop_.learning_rate;
      if (loop_.anneal_lr) {
        learning_rate *= 1.0 - static_cast<double>(steps_) / static_cast<double>(total_steps);
      }
      for (auto& group : optimizer_->param_groups()) group.options().set_lr(learning_rate);

      // Collect a rollout with the current policy, then GAE advantages and value targets.
      const Clock::time_point collect_start = Clock::now();
      collector_.collect(policy_, generator_, buffer());
      steps_ += static_cast<long>(buffer().rows()) * world_size(sync_.get());  // every rank's
      pipeline_.merge_statistics(sync_.get());
      buffer().compute_returns_and_advantages(loop_.gamma, loop_.gae_lambda);

      // The algorithm's update on it.
      const Clock::time_point update_start = Clock::now();
      {
        const ScopedTorchThreads threads(update_threads_);
        for (const auto& [name, value] : update()) {
          if (auto [it, first] = sums.try_emplace(name, value); !first) it->second += value;
        }
      }
      collect_seconds += seconds(collect_start, update_start);
      update_seconds += seconds(update_start, Clock::now());
      ++iteration;

      // Report: the mean of each loss over the updates since the last report.
      if (iteration % loop_.report_every != 0 && steps_ < total_steps) continue;
      const double updates = static_cast<double>((iteration - 1) % loop_.report_every + 1);
      const TrainStats stats =
          take_report(sums, updates, learning_rate, collect_seconds, update_seconds, start_steps,
                      seconds(start, Clock::now()));
      if (on_progress && !on_progress(stats)) break;
    }
  }

  void save(const std::filesystem::path& file) const override {
    save_policy_checkpoint(file, {.algorithm = algorithm_, .config = text_, .steps = steps_},
                           *policy_, *optimizer_, pipeline_, generator_,
                           [this](torch::serialize::OutputArchive& archive) {
                             if (returns_) write_return_statistics(archive, *returns_);
                           });
  }

  // A checkpoint saved with other return normalisation is refused: its value head learned
  // returns of another scale.
  void load(const std::filesystem::path& file) override {
    ReturnStatistics statistics;
    const auto check = [&](const CheckpointInfo& header, torch::serialize::InputArchive& archive) {
      check_saved_normalize_returns(header.config, returns_ != nullptr);
      if (returns_) statistics = read_return_statistics(archive);
    };
    steps_ = load_policy_checkpoint(file, algorithm_, observation_, *policy_, *optimizer_,
                                    pipeline_, generator_, check)
                 .steps;
    if (returns_) returns_->set_statistics(statistics);
    offset_generator(sync_.get(), generator_);
  }

  // The return normaliser's statistics (null: normalize_returns is off).
  const ReturnNormalizer* return_normalizer() const { return returns_.get(); }

  std::uint64_t parameter_hash() const override { return tensor_hash({parameters_.tensor()}); }

  void act(const envs::ObservationBuffers& observation, std::span<double> action,
           bool deterministic) override {
    act_gaussian(pipeline_, policy_, generator_, env_.action_space(), observation, scratch_, action,
                 deterministic);
  }

  // The value head's estimate of a state (the Self-Paced teacher's value estimator).
  double value(const envs::ObservationBuffers& observation) override {
    return state_value(pipeline_, policy_, observation, scratch_);
  }

 protected:
  template <typename Own>
  OnPolicyLearner(std::string algorithm, VecEnv& env, const LearnerOptions& options,
                  const OnPolicySettings<Own>& settings)
      : algorithm_(std::move(algorithm)),
        text_(settings.text),
        loop_(settings.loop),
        observation_(settings.observation),
        env_(env),
        generator_(at::make_generator<at::CPUGeneratorImpl>(options.seed)),
        pipeline_(env.observation_space(), observation_, find_touch(env)),
        policy_(pipeline_.shape(), env.action_space().size(), settings.policy, generator_),
        parameters_(*policy_),
        buffer_(loop_.n_steps, env.num_envs(), pipeline_.shape(), env.action_space().size()),
        returns_(make_return_normalizer(loop_, env, options)),
        collector_(env, pipeline_, chain_reward_hooks(options.reward_hook, returns_.get())),
        scratch_(ObsBatch::zeros(pipeline_.shape(), 1)),
        update_threads_(update_threads(options, pipeline_.shape())),
        sync_(options.sync) {
    // Data-parallel: every rank starts from rank 0's parameters.
    broadcast_tensor(sync_.get(), parameters_.tensor());
    if (loop_.overlap_update) start_overlap(env, settings.policy);
  }

  // The update on the rollout in buffer() (advantages and returns computed); returns its losses
  // and diagnostics by name (TrainStats::losses).
  virtual std::map<std::string, double> update() = 0;

  // What an update reads of the rollout's `rows` (advantages standardised when asked and there
  // are two or more), and the current policy on them.
  struct Batch {
    torch::Tensor actions, old_log_probs, old_values, returns, advantages;
    GaussianActorCriticImpl::Output out;  // the current mean and value
    torch::Tensor log_probs;              // of the actions, under the current policy
  };
  Batch evaluate(const torch::Tensor& rows, bool normalize_advantage) {
    Batch b;
    const RolloutBuffer& rollout = buffer();  // with overlap_update, the other one is filling
    const ObsBatch observations = rollout.observations.select(rows);
    b.actions = rollout.actions.index_select(0, rows);
    b.old_log_probs = rollout.log_probs.index_select(0, rows);
    b.old_values = rollout.values.index_select(0, rows);
    b.returns = rollout.returns.index_select(0, rows);
    b.advantages = rollout.advantages.index_select(0, rows);
    if (normalize_advantage && rows.size(0) > 1) b.advantages = standardize(b.advantages);
    b.out = policy_->forward(observations);
    b.log_probs = policy_->log_prob(b.out.mean, b.actions);
    return b;
  }

  // The actor-critic objective L = L_policy - ent_coef * entropy + vf_coef * L_value, with the
  // policy's current entropy.
  struct Loss {
    torch::Tensor entropy, total;
  };
  Loss actor_critic_loss(const torch::Tensor& policy_loss, const torch::Tensor& value_loss,
                         double ent_coef, double vf_coef) {
    const torch::Tensor entropy = policy_->entropy();
    return {entropy, policy_loss - ent_coef * entropy + vf_coef * value_loss};
  }

  // The mean standard deviation of the Gaussian policy, for the report.
  double policy_std() { return torch::exp(policy_->log_std()).mean().item<double>(); }

  // One optimiser step on `loss` (undefined: a zero gradient, for a data-parallel rank with no
  // transition), the gradient averaged over the ranks and its norm clipped to max_grad_norm.
  void gradient_step(const torch::Tensor& loss, double max_grad_norm) {
    parameters_.zero_grad();
    if (loss.defined()) loss.backward();
    average_gradients(sync_.get(), parameters_.tensor().grad());
    torch::nn::utils::clip_grad_norm_(parameters_.tensor(), max_grad_norm);
    optimizer_->step();
  }

  // The optimiser the algorithm built on parameters() (it must outlive the learn() calls): its
  // learning rate follows the schedule, and checkpoints hold its state.
  void use_optimizer(torch::optim::Optimizer& optimizer) { optimizer_ = &optimizer; }
  // The rollout the update reads (with overlap_update, the two buffers take turns).
  RolloutBuffer& buffer() { return *updating_; }
  GaussianActorCritic& policy() { return policy_; }
  PackedParameters& parameters() { return parameters_; }
  at::Generator& generator() { return generator_; }
  // The data-parallel ranks (null: alone).
  GradSync* sync() const { return sync_.get(); }

 private:
  // overlap_update: the actor copy and the second buffer; UserError for a data-parallel run.
  void start_overlap(const VecEnv& env, const PolicyConfig& policy);
  // learn() with overlap_update (see the top).
  void learn_overlapped(long total_steps, const ProgressFn& on_progress);
  // A report of both loops: the mean of each loss over `updates`, the learning rate, the seconds
  // since the last report (zeroed), the episodes the collector ended since then, and the env
  // steps per second since `start_steps` was the count; `sums` is emptied.
  TrainStats take_report(std::map<std::string, double>& sums, double updates, double learning_rate,
                         double& collect_seconds, double& update_seconds, long start_steps,
                         double elapsed_seconds);
  // The learning rate of the iteration that starts at `steps`: constant, or annealed linearly.
  double learning_rate_at(long steps, long total_steps) const {
    if (!loop_.anneal_lr) return loop_.learning_rate;
    return loop_.learning_rate *
           (1.0 - static_cast<double>(steps) / static_cast<double>(total_steps));
  }

  const std::string algorithm_;
  const std::string text_;  // every value, "name = value" lines
  const OnPolicyLoop loop_;
  const ObservationConfig observation_;
  VecEnv& env_;
  at::Generator generator_;
  ObservationPipeline pipeline_;
  GaussianActorCritic policy_;
  PackedParameters parameters_;                   // policy_'s parameters, packed for the optimiser
  torch::optim::Optimizer* optimizer_ = nullptr;  // the algorithm's, on parameters_
  RolloutBuffer buffer_;
  // overlap_update: the second rollout buffer and the collector thread's copy of the policy
  // (LibTorch modules may not be read while the optimiser writes them); empty otherwise.
  std::unique_ptr<RolloutBuffer> second_buffer_;
  GaussianActorCritic actor_{nullptr};
  RolloutBuffer* updating_ = &buffer_;
  std::unique_ptr<ReturnNormalizer> returns_;  // null: normalize_returns off
  RolloutCollector collector_;
  ObsBatch scratch_;  // one row, for act()
  const int update_threads_;
  const std::shared_ptr<GradSync> sync_;  // null: alone
  long steps_ = 0;
};

}  // namespace cradle::learn

#include "learn/on_policy.h"

#include <exception>
#include <thread>

#include "core/error.h"
#include "learn/vector_env.h"

namespace cradle::learn {

std::unique_ptr<ReturnNormalizer> make_return_normalizer(const OnPolicyLoop& loop,
                                                         const VecEnv& env,
                                                         const LearnerOptions& options) {
  if (!loop.normalize_returns) return nullptr;
  if (dynamic_cast<const AsyncVecEnv*>(&env) != nullptr) {
    throw UserError("normalize_returns needs a synchronous vector env (not an async one)");
  }
  if (distributed(options.sync.get())) {
    throw UserError(
        "normalize_returns is not available in data-parallel runs (each rank would "
        "scale its rewards by its own statistics)");
  }
  return std::make_unique<ReturnNormalizer>(loop.gamma);
}

RewardHook chain_reward_hooks(RewardHook first, ReturnNormalizer* returns) {
  if (!returns) return first;
  return [first = std::move(first), returns](const VecEnv& env, std::span<const double> actions,
                                             std::span<double> rewards) {
    if (first) first(env, actions, rewards);
    (*returns)(env, actions, rewards);
  };
}

void check_saved_normalize_returns(const std::string& config, bool wanted) {
  const std::map<std::string, std::string> values = parse_hyperparameter_text(config);
  const auto it = values.find("normalize_returns");
  const bool saved = it != values.end() && it->second == "true";
  if (saved == wanted) return;
  if (it == values.end()) {
    throw UserError(
        "normalize_returns is true but the checkpoint, of an earlier build, holds no return "
        "statistics (resume it with normalize_returns=false or start afresh)");
  }
  throw UserError(std::string("normalize_returns is ") + (wanted ? "true" : "false") +
                  " but the checkpoint was trained with normalize_returns = " +
                  (saved ? "true" : "false") + " (give the checkpoint's value)");
}

void write_return_statistics(torch::serialize::OutputArchive& archive,
                             const ReturnNormalizer& returns) {
  const ReturnStatistics& s = returns.statistics();
  archive.write("return_normalizer", torch::tensor({s.mean, s.var, s.count}, torch::kFloat64));
}

ReturnStatistics read_return_statistics(torch::serialize::InputArchive& archive) {
  torch::Tensor t;
  if (!archive.try_read("return_normalizer", t)) {
    throw UserError("normalize_returns is true but the checkpoint holds no return statistics");
  }
  if (t.scalar_type() != torch::kFloat64 || t.dim() != 1 || t.size(0) != 3) {
    throw UserError("the checkpoint's return statistics are not 3 float64 values");
  }
  const double* v = t.contiguous().data_ptr<double>();
  return {.mean = v[0], .var = v[1], .count = v[2]};
}

void OnPolicyLearner::start_overlap(const VecEnv& env, const PolicyConfig& policy) {
  if (distributed(sync_.get())) {
    throw UserError(algorithm_ +
                    ": overlap_update needs one process (not --distributed): the ranks' "
                    "observation statistics merge after each rollout, while the update runs");
  }
  second_buffer_ = std::make_unique<RolloutBuffer>(loop_.n_steps, env.num_envs(), pipeline_.shape(),
                                                   env.action_space().size());
  // Its initial values are overwritten before the first rollout: a generator of its own keeps
  // the learner's stream (and so every result) as without overlap.
  at::Generator scratch = at::make_generator<at::CPUGeneratorImpl>(0);
  actor_ = GaussianActorCritic(pipeline_.shape(), env.action_space().size(), policy, scratch);
}

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point from) {
  return std::chrono::duration<double>(Clock::now() - from).count();
}

// Copies every parameter and buffer of `from` into `to` (modules of the same layout).
void copy_module(torch::nn::Module& from, torch::nn::Module& to) {
  torch::NoGradGuard no_grad;
  const std::vector<torch::Tensor> source = from.parameters(), target = to.parameters();
  for (size_t i = 0; i < source.size(); ++i) target[i].copy_(source[i]);
  const std::vector<torch::Tensor> source_buffers = from.buffers(), target_buffers = to.buffers();
  for (size_t i = 0; i < source_buffers.size(); ++i) target_buffers[i].copy_(source_buffers[i]);
}

// Joins a thread however the scope ends (an update that throws waits for the rollout in flight:
// the collector thread uses the learner's members).
struct JoinOnExit {
  std::thread& thread;
  ~JoinOnExit() {
    if (thread.joinable()) thread.join();
  }
};

}  // namespace

TrainStats OnPolicyLearner::take_report(std::map<std::string, double>& sums, double updates,
                                        double learning_rate, double& collect_seconds,
                                        double& update_seconds, long start_steps,
                                        double elapsed_seconds) {
  TrainStats stats{.steps = steps_};
  for (const auto& [name, value] : sums) stats.losses[name] = value / updates;
  sums.clear();
  stats.losses["learning_rate"] = learning_rate;
  stats.losses["collect_seconds"] = std::exchange(collect_seconds, 0.0);
  stats.losses["update_seconds"] = std::exchange(update_seconds, 0.0);
  collector_.episodes().report_into(stats);
  stats.sps = static_cast<double>(steps_ - start_steps) / std::max(elapsed_seconds, 1e-9);
  return stats;
}

void OnPolicyLearner::learn_overlapped(long total_steps, const ProgressFn& on_progress) {
  const Clock::time_point start = Clock::now();
  const long start_steps = steps_;
  // As learn(): the env seed is drawn (and the envs reset) even when the budget is spent.
  collector_.start(draw_env_seed(generator_));
  if (returns_) returns_->start();
  if (steps_ >= total_steps) return;
  // The collector's own generator: the update draws its minibatches from generator_ meanwhile.
  at::Generator collect_generator =
      at::make_generator<at::CPUGeneratorImpl>(draw_env_seed(generator_));
  // The collector thread computes at this thread's LibTorch thread count (torch_threads), as the
  // synchronous collection does: a new thread starts at OpenMP's default (every core), and
  // another split of an operation may round differently.
  const int torch_threads = torch::get_num_threads();
  RolloutBuffer* collecting = second_buffer_.get();
  updating_ = &buffer_;
  double collect_seconds = 0, update_seconds = 0;  // since the last report (thread time each)
  std::map<std::string, double> sums;              // of the updates since the last report
  long updates = 0;                                // since the last report
  const auto collect = [&](RolloutBuffer& rollout) {
    const Clock::time_point begin = Clock::now();
    collector_.collect(actor_, collect_generator, rollout);
    return seconds_since(begin);
  };
  const auto update_on = [&](double learning_rate) {
    const Clock::time_point begin = Clock::now();
    for (auto& group : optimizer_->param_groups()) group.options().set_lr(learning_rate);
    const ScopedTorchThreads threads(update_threads_);
    for (const auto& [name, value] : update()) {
      if (auto [it, first] = sums.try_emplace(name, value); !first) it->second += value;
    }
    ++updates;
    update_seconds += seconds_since(begin);
  };
  // The report at the rollouts so far: the episodes they ended and the updates done since the
  // last report (none yet at the first). Returns on_progress's answer.
  const auto report = [&](double learning_rate) {
    const TrainStats stats =
        take_report(sums, static_cast<double>(std::max(updates, 1L)), learning_rate,
                    collect_seconds, update_seconds, start_steps, seconds_since(start));
    updates = 0;
    return !on_progress || on_progress(stats);
  };

  // Rollout 0, with nothing to update yet.
  copy_module(*policy_, *actor_);
  double learning_rate = learning_rate_at(steps_, total_steps);
  collect_seconds += collect(*updating_);
  steps_ += updating_->rows();
  updating_->compute_returns_and_advantages(loop_.gamma, loop_.gae_lambda);

  for (long iteration = 0;; ++iteration) {
    // Boundary k: nothing runs. Rollout k is in *updating_, the policy holds the updates before
    // k. The report comes here, before rollout k+1 starts, so that a report saying stop ends
    // learn() where the synchronous loop would: after update k, no rollout beyond k collected.
    if (steps_ >= total_steps) {
      update_on(learning_rate);
      report(learning_rate);
      return;
    }
    if ((iteration + 1) % loop_.report_every == 0 && !report(learning_rate)) {
      update_on(learning_rate);
      return;
    }

    // Rollout k+1 on the collector thread with the policy as it is now, update k here.
    copy_module(*policy_, *actor_);
    std::exception_ptr collect_error;
    double collected = 0;
    std::thread collector;
    const JoinOnExit join{collector};
    collector = std::thread([&] {
      try {
        const ScopedTorchThreads threads(torch_threads);
        collected = collect(*collecting);
      } catch (...) {
        collect_error = std::current_exception();
      }
    });
    update_on(learning_rate);
    collector.join();
    if (collect_error) std::rethrow_exception(collect_error);
    collect_seconds += collected;

    // Rollout k+1 becomes the one to update on.
    learning_rate = learning_rate_at(steps_, total_steps);
    steps_ += collecting->rows();
    collecting->compute_returns_and_advantages(loop_.gamma, loop_.gae_lambda);
    std::swap(updating_, collecting);
  }
}

}  // namespace cradle::learn

#include "learn/on_policy.h"

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

}  // namespace cradle::learn

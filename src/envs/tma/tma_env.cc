#include "envs/tma/tma_env.h"

#include <algorithm>

#include "envs/action_check.h"

namespace cradle::envs {
namespace {

DictSpace observation_space_of(const tma::TmaEnv& env) {
  return DictSpace{{{"observation", Box::unbounded({env.observation_size()}, DType::kFloat64)}}};
}

}  // namespace

TmaEnvAdapter::TmaEnvAdapter(const tma::TmaOptions& options, std::shared_ptr<const tma::Cppn> cppn)
    : env_(options, std::move(cppn)),
      observation_space_(observation_space_of(env_)),
      action_space_(Box::uniform({env_.action_size()}, DType::kFloat64, -1.0, 1.0)),
      buffers_(observation_space_) {
  success_slot_ = info_.declare("is_success", InfoType::kBool);
  failure_slot_ = info_.declare("is_failure", InfoType::kBool);
  copy_observation();
}

void TmaEnvAdapter::reset(std::optional<std::uint64_t> seed) {
  env_.reset(seed);
  info_.clear();
  copy_observation();
}

StepResult TmaEnvAdapter::step(std::span<const double> action) {
  check_finite_actions(action);
  const tma::TmaStep r = env_.step(action);
  info_.steps = env_.episode_steps() - 1;
  info_.set(success_slot_, r.success);
  info_.set(failure_slot_, r.terminated && r.reward == -100);
  copy_observation();
  return StepResult{.reward = r.reward, .terminated = r.terminated, .truncated = r.truncated};
}

void TmaEnvAdapter::copy_observation() {
  const std::span<const double> obs = env_.observation();
  std::copy(obs.begin(), obs.end(), buffers_.f64(0).begin());
}

}  // namespace cradle::envs

#include "envs/sami/sami_env.h"

#include <algorithm>

#include "envs/action_check.h"

namespace cradle::envs {

SamiEnvAdapter::SamiEnvAdapter(std::unique_ptr<sami::SamiEnv> env)
    : env_(std::move(env)),
      space_(env_->spec().observation_space()),
      action_space_(env_->spec().action_space()),
      buffers_(space_),
      success_slot_(info_.declare("is_success", InfoType::kBool)) {}

void SamiEnvAdapter::copy_observation() {
  // Key i of the family's flat float32 observation goes to buffer i.
  const auto& keys = env_->spec().keys;
  for (int i = 0; i < static_cast<int>(keys.size()); ++i) {
    const auto values = env_->observation(keys[i]);
    std::copy(values.begin(), values.end(), buffers_.f32(i).begin());
  }
  info_.steps = env_->info().steps;
  info_.set(success_slot_, env_->info().is_success);
}

void SamiEnvAdapter::reset(std::optional<std::uint64_t> seed) {
  env_->reset(seed);
  copy_observation();
}

StepResult SamiEnvAdapter::step(std::span<const double> action) {
  check_finite_actions(action);
  const sami::StepResult r = env_->step(action);
  copy_observation();
  return {.reward = r.reward, .terminated = r.terminated, .truncated = r.truncated};
}

std::unique_ptr<Env> make_sami_env(std::string_view name, std::string_view split,
                                   std::uint64_t seed) {
  return std::make_unique<SamiEnvAdapter>(sami::make_env(name, split, seed));
}

}  // namespace cradle::envs

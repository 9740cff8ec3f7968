#include "envs/sami/sami_env.h"

#include <algorithm>
#include <limits>
#include <string>

#include "core/error.h"
#include "envs/action_check.h"

namespace cradle::envs {

SamiEnvAdapter::SamiEnvAdapter(std::unique_ptr<sami::SamiEnv> env)
    : env_(std::move(env)),
      space_(env_->spec().observation_space()),
      action_space_(env_->spec().action_space()),
      buffers_(space_),
      success_slot_(info_.declare("is_success", InfoType::kBool)),
      base_sets_(env_->task_sets()) {}

void SamiEnvAdapter::set_reset_options(const ResetOptions& options) {
  const sami::Varies varies = sami::env_varies(env_->spec().id);
  const std::string env(env_->spec().name);
  auto value = [&](const std::string& name, double v, const double range[2]) {
    if (!(v >= range[0] && v <= range[1])) {
      throw UserError("reset option " + name + " = " + std::to_string(v) + " is out of range for " +
                      env + " (expected [" + std::to_string(range[0]) + ", " +
                      std::to_string(range[1]) + "])");
    }
    return v;
  };
  std::vector<sami::TaskSet> sets = base_sets_;
  for (const auto& [name, v] : options) {
    const bool factor = (name == "mass" && varies.mass) || (name == "damping" && varies.damping);
    const bool cell = (name == "table_friction" || name == "cube_mass") && varies.cells;
    if (!factor && !cell) {
      std::string known;
      if (varies.mass) known += "mass";
      if (varies.damping) known += known.empty() ? "damping" : ", damping";
      if (varies.cells) known += "table_friction, cube_mass";
      throw UserError("reset option '" + name + "' is not a hidden parameter of " + env +
                      " (expected " + (known.empty() ? "none" : known) + ")");
    }
    const double x = value(name, v, factor ? kFactorRange : kCellRange);
    for (sami::TaskSet& s : sets) {
      if (name == "mass") s.mass = {x};
      if (name == "damping") s.damping = {x};
      for (auto& c : s.cells) c[name == "table_friction" ? 0 : 1] = x;
    }
  }
  env_->set_task_sets(std::move(sets));
}

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

double SamiEnvAdapter::score() const {
  if (env_->spec().id != sami::EnvId::kPandaPush) return std::numeric_limits<double>::quiet_NaN();
  return env_->info().is_success ? 1.0 : 0.0;
}

StepResult SamiEnvAdapter::step(std::span<const double> action) {
  check_finite_actions(action);
  const sami::StepResult r = env_->step(action);
  copy_observation();
  return {.reward = r.reward, .terminated = r.terminated, .truncated = r.truncated};
}

std::vector<sami::TaskSet> sami_vector_sets(sami::EnvId id, std::string_view split_or_file) {
  return sami::one_set_per_env(sami::task_sets(id, split_or_file));
}

std::unique_ptr<Env> make_sami_env(std::string_view name, std::string_view split,
                                   std::uint64_t seed) {
  return std::make_unique<SamiEnvAdapter>(sami::make_env(name, split, seed));
}

}  // namespace cradle::envs

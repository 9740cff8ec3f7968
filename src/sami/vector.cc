#include "sami/vector.h"

#include <algorithm>

#include "core/error.h"

namespace cradle::sami {

SamiVector::SamiVector(EnvId id, std::vector<TaskSet> sets, std::uint64_t seed, int threads,
                       Options options)
    : pool_(threads) {
  validate(id, sets);
  // One compiled model for all; each sub-env gets one task set and its own seed stream.
  const ModelPtr model = compile_robot(env_spec(id).robot);
  Rng rng(seed);
  for (TaskSet& set : sets)
    envs_.push_back(make_env(id, {std::move(set)}, rng.derive(), model, options));
  const int n = size(), obs = spec().obs_size;
  obs_.assign(n * obs, 0.0f);
  final_obs_.assign(n * obs, 0.0f);
  rewards_.assign(n, 0.0);
  terminated_.assign(n, 0);
  truncated_.assign(n, 0);
  final_info_.resize(n);
  for (Info& info : final_info_) info.crippled.reserve(8);
}

void SamiVector::copy_observation(int i) {
  const auto o = envs_[i]->observation();
  std::copy(o.begin(), o.end(), obs_.begin() + i * spec().obs_size);
}

void SamiVector::reset(std::optional<std::uint64_t> seed) {
  pool_.parallel_for(size(), [&](int i) {
    envs_[i]->reset(seed ? std::optional<std::uint64_t>(*seed + i) : std::nullopt);
    copy_observation(i);
  });
}

void SamiVector::step(std::span<const double> actions) {
  const int a = spec().action_size;
  if (static_cast<int>(actions.size()) != size() * a) {
    throw UserError(spec().name + " vector: " + std::to_string(actions.size()) +
                    " action values; expected " + std::to_string(size()) + " x " +
                    std::to_string(a));
  }
  pool_.parallel_for(size(), [&](int i) {
    SamiEnv& env = *envs_[i];
    const StepResult r = env.step(actions.subspan(i * a, a));
    rewards_[i] = r.reward;
    terminated_[i] = r.terminated;
    truncated_[i] = r.truncated;
    if (r.terminated || r.truncated) {
      const auto o = env.observation();
      std::copy(o.begin(), o.end(), final_obs_.begin() + i * spec().obs_size);
      final_info_[i] = env.info();
      env.reset();
    }
    copy_observation(i);
  });
}

std::span<const float> SamiVector::final_observation(int i) const {
  return std::span<const float>(final_obs_).subspan(i * spec().obs_size, spec().obs_size);
}

}  // namespace cradle::sami

#include "train/sample_vector.h"

#include <memory>

#include "envs/mimo/sample_env.h"

namespace cradle::train {

TrainingVector make_sample_training(const std::string& name, int num_envs, int threads,
                                    std::uint64_t seed, const EnvWrapper& wrap) {
  using learn::ThreadedVecEnv;
  // One compiled scene for all; the reference's actuation unless muscles are asked for.
  envs::SampleOptions options;
  options.actuation = ActuationModel::kSpringDamper;
  const auto assets = envs::make_sample_assets(envs::sample_env_id(name), options);
  TrainingVector out;
  out.vec = std::make_unique<ThreadedVecEnv>(
      num_envs,
      [&](int i) {
        std::unique_ptr<envs::Env> env =
            envs::make_sample_env(assets, ThreadedVecEnv::env_seed(seed, i));
        return wrap ? wrap(std::move(env)) : std::move(env);
      },
      threads);
  out.end_episodes = [] {};
  return out;
}

}  // namespace cradle::train

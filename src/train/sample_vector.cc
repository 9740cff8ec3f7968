#include "train/sample_vector.h"

#include <memory>
#include <vector>

#include "envs/mimo/sample_env.h"

namespace cradle::train {

TrainingVector make_sample_training(const std::string& name, int num_envs, int threads,
                                    std::uint64_t seed, const EnvWrapper& wrap, int async_batch) {
  using learn::ThreadedVecEnv;
  // One compiled scene for all; the reference's actuation unless muscles are asked for.
  envs::SampleOptions options;
  options.actuation = ActuationModel::kSpringDamper;
  const auto assets = envs::make_sample_assets(envs::sample_env_id(name), options);
  TrainingVector out;
  auto make = [&](int i) {
    std::unique_ptr<envs::Env> env =
        envs::make_sample_env(assets, ThreadedVecEnv::env_seed(seed, i));
    return wrap ? wrap(std::move(env)) : std::move(env);
  };
  if (async_batch > 0) {
    std::vector<std::unique_ptr<envs::Env>> list;
    for (int i = 0; i < num_envs; ++i) list.push_back(make(i));
    out.vec = std::make_unique<learn::AsyncVecEnv>(std::move(list), async_batch, threads);
  } else {
    out.vec = std::make_unique<ThreadedVecEnv>(num_envs, make, threads);
  }
  out.end_episodes = [] {};
  return out;
}

}  // namespace cradle::train

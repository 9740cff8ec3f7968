#include "train/babybench_vector.h"

#include <stdexcept>

#include "envs/babybench.h"

namespace cradle::train {

std::unique_ptr<learn::ThreadedVecEnv> make_babybench_vec_env(const Config& config, int num_envs,
                                                              int threads, bool training,
                                                              std::uint64_t seed) {
  using learn::ThreadedVecEnv;
  if (num_envs < 1) throw std::invalid_argument("make_babybench_vec_env: num_envs < 1");
  // One compiled model for all; one training log shared by all (it is thread-safe).
  const auto assets = envs::make_assets(config);
  const std::shared_ptr<envs::TrainingLog> log = training ? envs::start_training(*assets) : nullptr;
  return std::make_unique<ThreadedVecEnv>(
      num_envs,
      [&](int i) {
        auto env = std::make_unique<envs::BabyBenchEnv>(assets, ThreadedVecEnv::env_seed(seed, i));
        if (log) env->attach_log(log);
        return env;
      },
      threads);
}

}  // namespace cradle::train

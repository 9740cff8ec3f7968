// A vector of MIMo sample envs (reach, standup, selfbody, catch) for `cradle train --env`: the
// family-specific half of a training run, as babybench_vector.h is for BabyBench configs.
#pragma once

#include <cstdint>
#include <string>

#include "train/babybench_vector.h"

namespace cradle::train {

// `num_envs` envs of the sample task `name` sharing one compiled scene (spring-damper actuation,
// as `cradle illustrate` without --use_muscles), env i seeded with ThreadedVecEnv::env_seed(seed,
// i) and wrapped by `wrap` when given. No training log (log null, end_episodes does nothing).
// async_batch > 0: an AsyncVecEnv returning batches of that many envs. UserError for an unknown
// name.
TrainingVector make_sample_training(const std::string& name, int num_envs, int threads,
                                    std::uint64_t seed, const EnvWrapper& wrap = nullptr,
                                    int async_batch = 0);

}  // namespace cradle::train

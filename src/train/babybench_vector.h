// A vector of BabyBench envs built from a config: the family-specific half of a training run
// (learners see only the VecEnv).
#pragma once

#include <cstdint>
#include <memory>

#include "core/config.h"
#include "learn/vector_env.h"

namespace cradle::train {

// BabyBench envs sharing one set of assets (one compiled model; each env still holds its own
// mjData: 5-34 MB with the scene sizes of scene::scene_sizes, 300 MB at the reference's
// njmax = 5000). training = true prepares
// <save_dir> as envs::make_env does and attaches one shared training log to every env, written in
// env order; continue_log >= 0 continues the log that holds that many entries (resume). Refuses
// (UserError) a vector that would not fit in memory.
std::unique_ptr<learn::ThreadedVecEnv> make_babybench_vec_env(const Config& config, int num_envs,
                                                              int threads, bool training,
                                                              std::uint64_t seed,
                                                              long continue_log = -1);

}  // namespace cradle::train

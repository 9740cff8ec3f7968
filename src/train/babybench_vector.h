// A vector of BabyBench envs built from a config: the family-specific half of a training run
// (learners see only the VecEnv).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>

#include "core/config.h"
#include "envs/training_log.h"
#include "learn/proc_vector_env.h"
#include "learn/vector_env.h"

namespace cradle::train {

// BabyBench envs sharing one set of assets (one compiled model; each env still holds its own
// mjData: 5-34 MB with the scene sizes of scene::scene_sizes, 300 MB at the reference's
// njmax = 5000). training = true prepares
// <save_dir> as envs::make_env does and attaches one shared training log to every env, written in
// env order; continue_log >= 0 continues the log that holds that many entries (resume). Refuses
// (UserError) a vector that would not fit in memory.
// `wrap`, when given, wraps each env (e.g. in a CurriculumEnv).
using EnvWrapper = std::function<std::unique_ptr<envs::Env>(std::unique_ptr<envs::Env>)>;
std::unique_ptr<learn::ThreadedVecEnv> make_babybench_vec_env(const Config& config, int num_envs,
                                                              int threads, bool training,
                                                              std::uint64_t seed,
                                                              long continue_log = -1,
                                                              const EnvWrapper& wrap = nullptr);

// The same envs in `procs` worker processes (learn::ProcVecEnv; num_envs a multiple of procs), so
// that envs which render draw in parallel; with training = true their training-log entries are
// written here, by the one log, in env order.
std::unique_ptr<learn::ProcVecEnv> make_babybench_proc_vec_env(const Config& config, int num_envs,
                                                               int procs, bool training,
                                                               std::uint64_t seed);

// A training vector and its training log, for the run's bookkeeping without knowing the family.
struct TrainingVector {
  // A ThreadedVecEnv (lock-step), or an AsyncVecEnv when built with async_batch > 0.
  std::unique_ptr<learn::VecEnv> vec;
  std::shared_ptr<envs::TrainingLog> log;  // shared by every env
  int geom_count = 0;                      // the model's geoms (the log's geom ids are below)
  // Records every env's current episode now, cut short (a checkpoint is an episode boundary).
  std::function<void()> end_episodes;
};

// make_babybench_vec_env with training = true. continue_log >= 0 (a resumed run): the log holding
// that many entries is continued and every env's first reset records nothing (the episode before
// it was never this run's). async_batch > 0: an AsyncVecEnv returning batches of that many envs
// (the same env seeds), whose log commits after every batch (env order within a commit). procs > 0:
// a ProcVecEnv of that many worker processes (no async_batch then).
TrainingVector make_babybench_training(const Config& config, int num_envs, int threads,
                                       std::uint64_t seed, long continue_log = -1,
                                       const EnvWrapper& wrap = nullptr, int async_batch = 0,
                                       int procs = 0);

}  // namespace cradle::train

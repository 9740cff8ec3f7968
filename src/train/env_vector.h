// A vector of envs of one registered id (envs/registry.h) for `cradle train --env ID`: the
// family-agnostic half of a training run, as babybench_vector.h is for BabyBench configs.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "core/config.h"
#include "envs/registry.h"
#include "train/babybench_vector.h"

namespace cradle::train {

// The registered id of an env name: an id, an alias or a MIMo sample task's short name. UserError
// naming the closest ids for an unknown one.
std::string registered_env_id(const std::string& name);

// The config a BabyBench id trains as (the registry's file, or the documented defaults); nullopt
// for an id of another family. UserError naming the closest ids for an unknown one.
std::optional<Config> babybench_config(const std::string& name);

// A UserError "<prefix>--envs N does not split evenly over --procs P; ..." unless P divides N.
void check_procs_split(int num_envs, int procs, const std::string& prefix = "");

// `num_envs` envs of `id` from one factory (what they share compiled once), env i made with
// index i and seed ThreadedVecEnv::env_seed(seed, i) and wrapped by `wrap` when given. No training
// log (log null, end_episodes does nothing). async_batch > 0: an AsyncVecEnv returning batches of
// that many envs; procs > 0: a ProcVecEnv, the envs made and stepped in that many worker
// processes (each its own GL context: envs that render draw in parallel), the same trajectories.
// UserError for an unknown id or option.
TrainingVector make_env_training(const std::string& id, int num_envs, int threads,
                                 std::uint64_t seed, const EnvWrapper& wrap = nullptr,
                                 int async_batch = 0, const envs::EnvOptions& options = {},
                                 int procs = 0);

}  // namespace cradle::train

#include "train/env_vector.h"

#include <memory>
#include <vector>

#include "core/error.h"
#include "learn/proc_vector_env.h"

namespace cradle::train {

void check_procs_split(int num_envs, int procs, const std::string& prefix) {
  if (num_envs % procs == 0) return;
  throw UserError(prefix + "--envs " + std::to_string(num_envs) +
                  " does not split evenly over --procs " + std::to_string(procs) +
                  "; give --envs a multiple of --procs");
}

TrainingVector make_env_training(const std::string& id, int num_envs, int threads,
                                 std::uint64_t seed, const EnvWrapper& wrap, int async_batch,
                                 const envs::EnvOptions& options, int procs) {
  using learn::ThreadedVecEnv;
  const envs::EnvMaker maker = envs::env_maker(id, options);
  TrainingVector out;
  auto make = [&](int i) {
    std::unique_ptr<envs::Env> env = maker(i, ThreadedVecEnv::env_seed(seed, i));
    return wrap ? wrap(std::move(env)) : std::move(env);
  };
  if (procs > 0) {
    // The factory runs in each worker after the fork: what the maker compiled here is shared
    // copy-on-write.
    out.vec = std::make_unique<learn::ProcVecEnv>(num_envs, make, procs);
  } else if (async_batch > 0) {
    std::vector<std::unique_ptr<envs::Env>> list;
    for (int i = 0; i < num_envs; ++i) list.push_back(make(i));
    out.vec = std::make_unique<learn::AsyncVecEnv>(std::move(list), async_batch, threads);
  } else {
    out.vec = std::make_unique<ThreadedVecEnv>(num_envs, make, threads);
  }
  out.end_episodes = [] {};
  return out;
}

std::string registered_env_id(const std::string& name) {
  // `cradle illustrate`'s short names of the MIMo sample tasks.
  for (const char* short_name : {"reach", "standup", "selfbody", "catch"})
    if (name == short_name) return "mimo/" + name;
  return envs::env_spec(name).id;  // UserError naming the closest ids
}

std::optional<Config> babybench_config(const std::string& name) {
  const envs::EnvSpec spec = envs::env_spec(registered_env_id(name));
  if (spec.family != "babybench") return std::nullopt;
  return spec.config.empty() ? default_config() : load_config(spec.config);
}

}  // namespace cradle::train

#include "sami/throughput.h"

#include <time.h>

#include <algorithm>
#include <vector>

#include "core/rng.h"
#include "sami/env.h"

namespace cradle::sami {

Throughput measure_throughput(EnvId id, long steps, std::uint64_t seed) {
  auto env = make_env(id, split_sets(id, Split::kTrain), seed);
  const Spec& spec = env->spec();
  const mjModel* m = env->shared_model();
  mjData* bare = mj_makeData(m);
  // A fixed table of random actions, cycled by both loops.
  Rng rng(seed + 1);
  std::vector<double> actions(64 * spec.action_size);
  for (double& a : actions) a = rng.uniform(spec.action_low, spec.action_high);
  auto action = [&](long t) {
    return std::span<const double>(actions).subspan((t % 64) * spec.action_size, spec.action_size);
  };
  env->reset(seed);
  mj_copyData(bare, m, env->data());
  // Thread CPU time: other processes on a shared machine do not count.
  auto now = [] {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return t.tv_sec + 1e-9 * t.tv_nsec;
  };
  double env_s = 0, bare_s = 0;
  constexpr long kBlock = 500;
  long env_t = 0, bare_t = 0;
  for (long done = 0; done < steps; done += kBlock) {
    const long n = std::min(kBlock, steps - done);
    // Env steps.
    double start = now();
    for (long i = 0; i < n; ++i, ++env_t) {
      const StepResult r = env->step(action(env_t));
      if (r.terminated || r.truncated) env->reset();
    }
    env_s += now() - start;
    // The same number of bare blocks of frame_skip mj_steps.
    start = now();
    for (long i = 0; i < n; ++i, ++bare_t) {
      const auto a = action(bare_t);
      for (int u = 0; u < spec.action_size && u < m->nu; ++u) bare->ctrl[u] = a[u];
      for (int k = 0; k < spec.frame_skip; ++k) mj_step(m, bare);
      if ((bare_t + 1) % spec.horizon == 0) mj_resetData(m, bare);
    }
    bare_s += now() - start;
  }
  mj_deleteData(bare);
  return {.env_steps_per_s = steps / env_s,
          .bare_steps_per_s = steps / bare_s,
          .ratio = env_s / bare_s};
}

}  // namespace cradle::sami

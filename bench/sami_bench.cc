// SaMI envs: one env step against the bare mj_steps it contains (frame_skip mj_step calls on the
// shared model), per env, on one core. Targets: Half-Cheetah >= 20,000 env steps/s, Panda push
// >= 2,000, env / bare <= 1.1 (`cradle sami bench --env all` measures the ratio in one run).
#include <benchmark/benchmark.h>

#include <string>
#include <vector>

#include "core/rng.h"
#include "sami/env.h"

namespace {

using cradle::sami::EnvId;

std::vector<double> random_actions(const cradle::sami::Spec& spec) {
  cradle::Rng rng(1);
  std::vector<double> actions(64 * spec.action_size);
  for (double& a : actions) a = rng.uniform(spec.action_low, spec.action_high);
  return actions;
}

void BM_SamiEnvStep(benchmark::State& state, EnvId id) {
  auto env =
      cradle::sami::make_env(id, cradle::sami::split_sets(id, cradle::sami::Split::kTrain), 0);
  const int n = env->spec().action_size;
  const std::vector<double> actions = random_actions(env->spec());
  env->reset(0);
  long t = 0;
  for (auto _ : state) {
    const auto r = env->step(std::span<const double>(actions).subspan((t++ % 64) * n, n));
    if (r.terminated || r.truncated) env->reset();
  }
  state.SetItemsProcessed(state.iterations());
}

void BM_SamiBareSteps(benchmark::State& state, EnvId id) {
  auto env =
      cradle::sami::make_env(id, cradle::sami::split_sets(id, cradle::sami::Split::kTrain), 0);
  const cradle::sami::Spec& spec = env->spec();
  const mjModel* m = env->shared_model();
  env->reset(0);
  mjData* d = mj_makeData(m);
  mj_copyData(d, m, env->data());
  const std::vector<double> actions = random_actions(spec);
  long t = 0;
  for (auto _ : state) {
    for (int u = 0; u < spec.action_size && u < m->nu; ++u) {
      d->ctrl[u] = actions[(t % 64) * spec.action_size + u];
    }
    for (int k = 0; k < spec.frame_skip; ++k) mj_step(m, d);
    if (++t % spec.horizon == 0) mj_resetData(m, d);
  }
  mj_deleteData(d);
  state.SetItemsProcessed(state.iterations());
}

// Registered once at start-up for every env of the family.
const bool kRegistered = [] {
  for (EnvId id : cradle::sami::all_envs()) {
    const std::string name(cradle::sami::env_name(id));
    benchmark::RegisterBenchmark(("BM_SamiEnvStep/" + name).c_str(), BM_SamiEnvStep, id);
    benchmark::RegisterBenchmark(("BM_SamiBareSteps/" + name).c_str(), BM_SamiBareSteps, id);
  }
  return true;
}();

}  // namespace

// Google Benchmark targets for MIMo's sample envs: one env step with random actions (episodes
// restart when they end), so items_per_second is env steps per second.
#include <benchmark/benchmark.h>

#include <vector>

#include "core/rng.h"
#include "envs/mimo/sample_env.h"

namespace cradle {
namespace {

void BM_SampleEnvStep(benchmark::State& state, const char* name) {
  envs::SampleOptions options;
  options.vision_resolution = 64;  // benchmark and showroom eyes; the reference's is 256
  auto env = envs::make_sample_env(name, options, 0);
  const Box& space = env->action_space();
  Rng rng(1);
  std::vector<std::vector<double>> actions(64, std::vector<double>(space.size()));
  for (auto& action : actions) {
    for (size_t k = 0; k < action.size(); ++k) action[k] = rng.uniform(space.low[k], space.high[k]);
  }
  size_t t = 0;
  for (auto _ : state) {
    const envs::StepResult r = env->step(actions[t++ % actions.size()]);
    if (r.terminated || r.truncated) env->reset();
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK_CAPTURE(BM_SampleEnvStep, reach, "MIMoReach-v0");
BENCHMARK_CAPTURE(BM_SampleEnvStep, standup, "MIMoStandup-v0");
BENCHMARK_CAPTURE(BM_SampleEnvStep, selfbody, "MIMoSelfBody-v0");
BENCHMARK_CAPTURE(BM_SampleEnvStep, catch, "MIMoCatch-v0");
BENCHMARK_CAPTURE(BM_SampleEnvStep, bench_v1, "MIMoBench-v0");
BENCHMARK_CAPTURE(BM_SampleEnvStep, showroom, "MIMoShowroom-v0");

}  // namespace
}  // namespace cradle

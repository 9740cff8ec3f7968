// Google Benchmark target for the threaded vector env: self-touch env steps per second for N envs
// on T threads (items_per_second counts env steps, so linear scaling doubles it from 1/1 to 2/2).
// CPU is the whole process's: about N times one env's step when the threads do not slow each
// other down.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <vector>

#include "core/rng.h"
#include "learn/vector_env.h"

namespace cradle {
namespace {

void BM_VecEnvSelfTouch(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const int threads = static_cast<int>(state.range(1));
  const Config config =
      load_config(std::filesystem::path(CRADLE_SOURCE_DIR) / "configs" / "config_selftouch.yml");
  const auto vec = learn::make_babybench_vec_env(config, n, threads, /*training=*/false, 0);
  vec->reset(0);
  const Box& space = vec->action_space();
  const size_t dim = space.low.size();
  // Pre-drawn random actions, so the timed loop is the vector's step alone.
  Rng rng(1);
  std::vector<std::vector<double>> actions(64, std::vector<double>(n * dim));
  for (auto& batch : actions) {
    for (size_t j = 0; j < batch.size(); ++j) {
      batch[j] = rng.uniform(space.low[j % dim], space.high[j % dim]);
    }
  }
  size_t t = 0;
  for (auto _ : state) vec->step(actions[t++ % actions.size()]);
  state.SetItemsProcessed(state.iterations() * n);
}
BENCHMARK(BM_VecEnvSelfTouch)
    ->ArgNames({"envs", "threads"})
    ->Args({1, 1})
    ->Args({2, 2})
    ->Args({4, 2})
    ->Args({8, 2})
    ->UseRealTime()
    ->MeasureProcessCPUTime();

}  // namespace
}  // namespace cradle

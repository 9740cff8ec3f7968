// Memory per env and MuJoCo's size high-water marks.
//
//   build/cradle_bench --benchmark_filter=EnvMemory        resident MB per env, 1 / 2 / 8 envs
//   build/cradle_bench --benchmark_filter=SizeHighWater    max contacts, constraints, stack use
//
// EnvMemory: the process's resident set grows by `rss_mb` when a vector of N envs of a reference
// config is built and stepped (random actions, random starts); `rss_per_env_mb` is that over N,
// the shared compiled model included. SizeHighWater: one env for 20,000 random steps from random
// starts, reporting the largest ncon, nefc and stack use (MuJoCo's maxuse_*) against the sizes
// the scene was compiled with (nconmax, njmax, nstack): what sized them.
#include <benchmark/benchmark.h>
#include <malloc.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/config.h"
#include "core/rng.h"
#include "envs/babybench.h"
#include "train/babybench_vector.h"

namespace cradle {
namespace {

double resident_mb() {
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stod(line.substr(6)) / 1024;
  }
  return 0;
}

Config bench_config(const char* file) {
  Config config = load_config(std::string(CRADLE_SOURCE_DIR) + "/configs/" + file);
  config.save_dir = (std::filesystem::temp_directory_path() / "cradle_memory_bench").string();
  return config;
}

// Random actions within the bounds for every env of a vector.
void random_actions(Rng& rng, const Box& space, std::vector<double>& actions) {
  for (size_t k = 0; k < actions.size(); ++k) {
    const size_t j = k % space.size();
    actions[k] = rng.uniform(space.low[j], space.high[j]);
  }
}

void BM_EnvMemory(benchmark::State& state, const char* file) {
  const Config config = bench_config(file);
  const int n = static_cast<int>(state.range(0));
  for (auto _ : state) {
    malloc_trim(0);
    const double before = resident_mb();
    {
      auto vec = train::make_babybench_vec_env(config, n, 2, /*training=*/false, 0);
      for (int i = 0; i < n; ++i) vec->env(i).set_reset_options({{"randomize_start", 1}});
      std::vector<double> actions(static_cast<size_t>(n) * vec->action_space().size());
      Rng rng(1);
      vec->reset(0);
      for (int t = 0; t < 200; ++t) {
        random_actions(rng, vec->action_space(), actions);
        vec->step(actions);
      }
      const double grown = resident_mb() - before;
      state.counters["rss_mb"] = grown;
      state.counters["rss_per_env_mb"] = grown / n;
    }
    malloc_trim(0);
  }
}
BENCHMARK_CAPTURE(BM_EnvMemory, self_touch, "config_selftouch.yml")
    ->Arg(1)
    ->Arg(2)
    ->Arg(8)
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_EnvMemory, hand_regard, "config_handregard.yml")
    ->Arg(1)
    ->Arg(2)
    ->Arg(8)
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_EnvMemory, test_installation, "config_test_installation.yml")
    ->Arg(1)
    ->Arg(2)
    ->Arg(8)
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);

void BM_SizeHighWater(benchmark::State& state, const char* file) {
  Config config = bench_config(file);
  config.vision_active = false;  // physics only
  const auto assets = envs::make_assets(config);
  const mjModel* m = assets->model.get();
  for (auto _ : state) {
    envs::BabyBenchEnv env(assets, 0);
    env.set_randomize_start(true);
    std::vector<double> action(env.action_space().size());
    Rng rng(2);
    int max_con = 0, max_efc = 0;
    long max_stack = 0, warnings = 0;
    env.reset(0);
    for (int t = 0; t < 20000; ++t) {
      random_actions(rng, env.action_space(), action);
      const envs::StepResult r = env.step(action);
      const mjData* d = env.data();
      max_con = std::max(max_con, static_cast<int>(d->maxuse_con));
      max_efc = std::max(max_efc, static_cast<int>(d->maxuse_efc));
      max_stack = std::max(max_stack, static_cast<long>(d->maxuse_stack));
      if (r.terminated || r.truncated) {
        for (int w = 0; w < mjNWARNING; ++w) warnings += d->warning[w].number;
        env.reset();
      }
    }
    state.counters["max_ncon"] = max_con;
    state.counters["nconmax"] = m->nconmax;
    state.counters["max_nefc"] = max_efc;
    state.counters["njmax"] = m->njmax;
    state.counters["max_stack"] = static_cast<double>(max_stack);
    state.counters["nstack"] = static_cast<double>(m->nstack);
    state.counters["warnings"] = static_cast<double>(warnings);
  }
}
BENCHMARK_CAPTURE(BM_SizeHighWater, self_touch, "config_selftouch.yml")
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(BM_SizeHighWater, hand_regard, "config_handregard.yml")
    ->Iterations(1)
    ->Unit(benchmark::kSecond);
BENCHMARK_CAPTURE(BM_SizeHighWater, test_installation, "config_test_installation.yml")
    ->Iterations(1)
    ->Unit(benchmark::kSecond);

}  // namespace
}  // namespace cradle

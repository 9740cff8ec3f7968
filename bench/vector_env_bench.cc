// Google Benchmark target for the threaded vector env: self-touch env steps per second for N envs
// on T threads (items_per_second counts env steps, so linear scaling doubles it from 1/1 to 2/2).
// CPU is the whole process's: about N times one env's step when the threads do not slow each
// other down.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <span>
#include <thread>
#include <vector>

#include "core/rng.h"
#include "envs/babybench.h"
#include "learn/vector_env.h"
#include "train/babybench_vector.h"

namespace cradle {
namespace {

void BM_VecEnvSelfTouch(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const int threads = static_cast<int>(state.range(1));
  const Config config =
      load_config(std::filesystem::path(CRADLE_SOURCE_DIR) / "configs" / "config_selftouch.yml");
  const auto vec = train::make_babybench_vec_env(config, n, threads, /*training=*/false, 0);
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

// The 2-env scaling target, measured so that the host's drift cancels: each iteration times, back
// to back, 1 env on 1 thread, 2 envs on 2 threads (the vector), and 2 envs stepping freely on 2
// threads with no synchronisation (the machine's ceiling: what two independent processes get).
// Counters: vec_scaling = 2/2 over 1/1 steps/s; free_scaling = ceiling over 1/1;
// vec_of_free = vec_scaling / free_scaling (what the vector's lock-step costs);
// lockstep_bound = the best lock-step scaling two perfect cores could give, from the vector's own
// two envs stepped alternately on one thread: (sum of both step times) / (sum of the slower one's),
// since each vector step waits for the slower env.
void BM_VecEnvScalingSelfTouch(benchmark::State& state) {
  using Clock = std::chrono::steady_clock;
  constexpr int kSteps = 100;  // vector steps per slice (about 40 ms)
  const Config config =
      load_config(std::filesystem::path(CRADLE_SOURCE_DIR) / "configs" / "config_selftouch.yml");
  const auto one = train::make_babybench_vec_env(config, 1, 1, /*training=*/false, 0);
  const auto two = train::make_babybench_vec_env(config, 2, 2, /*training=*/false, 0);
  const auto assets = envs::make_assets(config);
  envs::BabyBenchEnv free_a(assets, 1), free_b(assets, 2);
  envs::BabyBenchEnv seq_a(assets, learn::ThreadedVecEnv::env_seed(0, 0));
  envs::BabyBenchEnv seq_b(assets, learn::ThreadedVecEnv::env_seed(0, 1));
  one->reset(0);
  two->reset(0);
  free_a.reset();
  free_b.reset();
  seq_a.reset();
  seq_b.reset();
  const Box& space = one->action_space();
  const size_t dim = space.low.size();
  Rng rng(1);
  std::vector<std::vector<double>> actions(kSteps, std::vector<double>(2 * dim));
  for (auto& batch : actions) {
    for (size_t j = 0; j < batch.size(); ++j) {
      batch[j] = rng.uniform(space.low[j % dim], space.high[j % dim]);
    }
  }
  const auto seconds = [](Clock::time_point since) {
    return std::chrono::duration<double>(Clock::now() - since).count();
  };
  // A free env's slice on its own thread: its steps/s.
  const auto run_free = [&](envs::BabyBenchEnv& env, double& rate) {
    const Clock::time_point start = Clock::now();
    for (int t = 0; t < kSteps; ++t) {
      if (env.step(std::span(actions[t]).first(dim)).truncated) env.reset();
    }
    rate = kSteps / seconds(start);
  };
  // One env step's duration.
  const auto timed_step = [&](envs::BabyBenchEnv& env, std::span<const double> action) {
    const Clock::time_point start = Clock::now();
    if (env.step(action).truncated) env.reset();
    return seconds(start);
  };
  double one_time = 0, two_time = 0, free_rate = 0, seq_sum = 0, seq_max = 0;
  long rounds = 0;
  for (auto _ : state) {
    Clock::time_point start = Clock::now();
    for (int t = 0; t < kSteps; ++t) one->step(std::span(actions[t]).first(dim));
    one_time += seconds(start);
    start = Clock::now();
    for (int t = 0; t < kSteps; ++t) two->step(actions[t]);
    two_time += seconds(start);
    double rate_a = 0, rate_b = 0;
    std::thread other([&] { run_free(free_b, rate_b); });
    run_free(free_a, rate_a);
    other.join();
    free_rate += rate_a + rate_b;
    for (int t = 0; t < kSteps; ++t) {
      const double a = timed_step(seq_a, std::span(actions[t]).first(dim));
      const double b = timed_step(seq_b, std::span(actions[t]).last(dim));
      seq_sum += a + b;
      seq_max += std::max(a, b);
    }
    ++rounds;
  }
  const double one_rate = rounds * kSteps / one_time;
  const double two_rate = 2.0 * rounds * kSteps / two_time;
  state.counters["one_env_sps"] = one_rate;
  state.counters["vec_scaling"] = two_rate / one_rate;
  state.counters["free_scaling"] = free_rate / rounds / one_rate;
  state.counters["vec_of_free"] = two_rate / (free_rate / rounds);
  state.counters["lockstep_bound"] = seq_sum / seq_max;
}
BENCHMARK(BM_VecEnvScalingSelfTouch)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace cradle

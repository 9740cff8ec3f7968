// Google Benchmark target for the threaded vector env: self-touch env steps per second for N envs
// on T threads (items_per_second counts env steps, so linear scaling doubles it from 1/1 to 2/2).
// CPU is the whole process's: about N times one env's step when the threads do not slow each
// other down.
#include <benchmark/benchmark.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <memory>
#include <span>
#include <thread>
#include <vector>

#include "core/rng.h"
#include "envs/babybench.h"
#include "learn/rollout.h"
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

// The async vector env's target, measured so that the host's drift cancels: each iteration
// runs, back to back, three slices of the same work (`kStepsPerEnv` steps of each of N self-touch
// envs, a separate set of envs for each) on 2 threads:
// - ceiling: each of 2 threads steps its own N/2 envs round robin with no synchronisation at all;
// - lock-step: ThreadedVecEnv, a barrier per vector step;
// - async: AsyncVecEnv with batch B, the caller re-sending each batch as it comes back.
// Counters: env steps per second of each, and async_of_ceiling, lockstep_of_ceiling (target:
// async >= 0.95 of the ceiling). On a loaded host async's third thread (the caller) can win it a
// larger share of the cores than the ceiling's two, so the *_cpu_of_ceiling counters compare env
// steps per second of process CPU time instead (polling and wake-ups cost CPU; load share does not
// enter).
void BM_AsyncVecEnvSelfTouch(benchmark::State& state) {
  using Clock = std::chrono::steady_clock;
  constexpr int kStepsPerEnv = 100;
  const int n = static_cast<int>(state.range(0));
  const int batch = static_cast<int>(state.range(1));
  const Config config =
      load_config(std::filesystem::path(CRADLE_SOURCE_DIR) / "configs" / "config_selftouch.yml");
  const auto assets = envs::make_assets(config);
  const auto make_list = [&] {
    std::vector<std::unique_ptr<envs::Env>> list;
    for (int i = 0; i < n; ++i) {
      list.push_back(
          std::make_unique<envs::BabyBenchEnv>(assets, learn::ThreadedVecEnv::env_seed(0, i)));
    }
    return list;
  };
  std::vector<std::unique_ptr<envs::Env>> free_envs = make_list();
  for (auto& env : free_envs) env->reset(0);
  learn::ThreadedVecEnv lockstep(make_list(), 2);
  learn::AsyncVecEnv async(make_list(), batch, 2);
  lockstep.reset(0);
  async.reset(0);
  const Box& space = lockstep.action_space();
  const size_t dim = space.low.size();
  // Pre-drawn actions: row t holds every env's action for its t-th step of a slice.
  Rng rng(1);
  std::vector<std::vector<double>> actions(kStepsPerEnv, std::vector<double>(n * dim));
  for (auto& row : actions) {
    for (size_t j = 0; j < row.size(); ++j)
      row[j] = rng.uniform(space.low[j % dim], space.high[j % dim]);
  }
  const auto seconds = [](Clock::time_point since) {
    return std::chrono::duration<double>(Clock::now() - since).count();
  };
  // Thread t's share of the ceiling: envs t, t + 2, ... round robin.
  const auto run_free = [&](int t) {
    for (int k = 0; k < kStepsPerEnv; ++k) {
      for (int e = t; e < n; e += 2) {
        const envs::StepResult r = free_envs[e]->step(std::span(actions[k]).subspan(e * dim, dim));
        if (r.terminated || r.truncated) free_envs[e]->reset();
      }
    }
  };
  std::vector<int> ids(n), steps(n);
  std::vector<double> batch_actions(n * dim);
  // Process CPU seconds.
  const auto cpu = [] {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
  };
  double free_time = 0, lockstep_time = 0, async_time = 0;
  double free_cpu = 0, lockstep_cpu = 0, async_cpu = 0;
  long rounds = 0, async_steps = 0;
  for (auto _ : state) {
    Clock::time_point start = Clock::now();
    double cpu_start = cpu();
    std::thread other([&] { run_free(1); });
    run_free(0);
    other.join();
    free_time += seconds(start);
    free_cpu += cpu() - cpu_start;

    start = Clock::now();
    cpu_start = cpu();
    for (int k = 0; k < kStepsPerEnv; ++k) lockstep.step(actions[k]);
    lockstep_time += seconds(start);
    lockstep_cpu += cpu() - cpu_start;

    // Every env sent, then each batch re-sent as it returns, until every env took its steps.
    start = Clock::now();
    cpu_start = cpu();
    for (int e = 0; e < n; ++e) ids[e] = e;
    std::fill(steps.begin(), steps.end(), 0);
    async.send(actions[0], ids);
    for (int running = n; running > 0;) {
      const learn::AsyncVecEnv::Batch b = async.recv();
      ids.clear();
      batch_actions.clear();
      for (int e : b.ids) {
        ++async_steps;
        if (++steps[e] == kStepsPerEnv) {
          --running;
          continue;
        }
        ids.push_back(e);
        const double* a = actions[steps[e]].data() + e * dim;
        batch_actions.insert(batch_actions.end(), a, a + dim);
      }
      if (!ids.empty()) async.send(batch_actions, ids);
    }
    async_time += seconds(start);
    async_cpu += cpu() - cpu_start;
    ids.resize(n);
    ++rounds;
  }
  const double work = static_cast<double>(rounds) * n * kStepsPerEnv;
  const double ceiling = work / free_time, locked = work / lockstep_time;
  const double async_rate = async_steps / async_time;
  state.counters["ceiling_sps"] = ceiling;
  state.counters["lockstep_sps"] = locked;
  state.counters["async_sps"] = async_rate;
  state.counters["lockstep_of_ceiling"] = locked / ceiling;
  state.counters["async_of_ceiling"] = async_rate / ceiling;
  const double ceiling_per_cpu = work / free_cpu;
  state.counters["lockstep_cpu_of_ceiling"] = work / lockstep_cpu / ceiling_per_cpu;
  state.counters["async_cpu_of_ceiling"] = async_steps / async_cpu / ceiling_per_cpu;
}
BENCHMARK(BM_AsyncVecEnvSelfTouch)
    ->ArgNames({"envs", "batch"})
    ->Args({4, 2})
    ->Args({8, 4})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// PPO's collection on self-touch, lock-step (ThreadedVecEnv) against async (AsyncVecEnv, batch
// envs / 2), N envs on 2 threads: one rollout of 64 steps per env with SB3's default policy (64-64
// tanh MLPs, pooled touch, normalised observations), one LibTorch thread. items_per_second counts
// env steps.
void BM_PpoCollectSelfTouch(benchmark::State& state) {
  constexpr int kSteps = 64;
  const int n = static_cast<int>(state.range(0));
  const bool async = state.range(1) != 0;
  torch::set_num_threads(1);
  const Config config =
      load_config(std::filesystem::path(CRADLE_SOURCE_DIR) / "configs" / "config_selftouch.yml");
  const auto assets = envs::make_assets(config);
  std::vector<std::unique_ptr<envs::Env>> list;
  for (int i = 0; i < n; ++i) {
    list.push_back(
        std::make_unique<envs::BabyBenchEnv>(assets, learn::ThreadedVecEnv::env_seed(0, i)));
  }
  std::unique_ptr<learn::VecEnv> vec;
  if (async) {
    vec = std::make_unique<learn::AsyncVecEnv>(std::move(list), n / 2, 2);
  } else {
    vec = std::make_unique<learn::ThreadedVecEnv>(std::move(list), 2);
  }
  at::Generator generator = at::make_generator<at::CPUGeneratorImpl>(0);
  const learn::ObservationConfig observation_config;
  learn::ObservationPipeline pipeline(vec->observation_space(), observation_config,
                                      learn::find_touch(*vec));
  const learn::PolicyConfig policy_config;
  learn::GaussianActorCritic policy(pipeline.shape(), vec->action_space().size(), policy_config,
                                    generator);
  learn::RolloutBuffer buffer(kSteps, n, pipeline.shape(), vec->action_space().size());
  learn::RolloutCollector collector(*vec, pipeline, nullptr);
  collector.start(0);
  for (auto _ : state) collector.collect(policy, generator, buffer);
  state.SetItemsProcessed(state.iterations() * kSteps * n);
}
BENCHMARK(BM_PpoCollectSelfTouch)
    ->ArgNames({"envs", "async"})
    ->Args({4, 0})
    ->Args({4, 1})
    ->Args({8, 0})
    ->Args({8, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace cradle

// Google Benchmark targets for TeachMyAgent: a Stump Tracks env step against the bare
// b2World::Step it contains (same world, same motor commands), a Parkour reset (CPPN terrain and
// bodies), the CPPN alone and a rendered frame.
#include <benchmark/benchmark.h>

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "core/rng.h"
#include "tma/render.h"
#include "tma/tma_env.h"

namespace cradle::tma {
namespace {

std::unique_ptr<TmaEnv> stump_env(const char* body) {
  auto env = std::make_unique<TmaEnv>(TmaOptions{.env = EnvId::kStumpTracks, .body = body});
  env->set_environment({{"stump_height", {1.0}}, {"obstacle_spacing", {3.0}}});
  env->reset(0);
  return env;
}

// Env steps on random actions; episodes that end are reset outside the timing.
void time_random_steps(benchmark::State& state, TmaEnv& env) {
  Rng rng(1);
  std::vector<double> a(env.action_size());
  for (auto _ : state) {
    for (double& v : a) v = rng.uniform(-1, 1);
    const TmaStep r = env.step(a);
    if (r.terminated || r.truncated) {
      state.PauseTiming();
      env.reset();
      state.ResumeTiming();
    }
  }
}

void BM_StumpTracksStep(benchmark::State& state, const char* body) {
  time_random_steps(state, *stump_env(body));
}
BENCHMARK_CAPTURE(BM_StumpTracksStep, old_classic_bipedal, "old_classic_bipedal");
BENCHMARK_CAPTURE(BM_StumpTracksStep, small_bipedal, "small_bipedal");
BENCHMARK_CAPTURE(BM_StumpTracksStep, spider, "spider");

// The bare physics of the same env: motors set as the env does, then b2World::Step only.
void BM_StumpTracksBareStep(benchmark::State& state, const char* body) {
  const auto holder = stump_env(body);
  TmaEnv& env = *holder;
  Rng rng(1);
  std::vector<double> a(env.action_size());
  int n = 0;
  for (auto _ : state) {
    for (double& v : a) v = rng.uniform(-1, 1);
    env.agent().activate_motors(a);
    env.world().Step(static_cast<float>(1.0 / kFps), kVelocityIterations, kPositionIterations);
    if (++n % 500 == 0) {
      state.PauseTiming();
      env.reset();
      state.ResumeTiming();
    }
  }
}
BENCHMARK_CAPTURE(BM_StumpTracksBareStep, old_classic_bipedal, "old_classic_bipedal");
BENCHMARK_CAPTURE(BM_StumpTracksBareStep, small_bipedal, "small_bipedal");
BENCHMARK_CAPTURE(BM_StumpTracksBareStep, spider, "spider");

void BM_ParkourReset(benchmark::State& state, const char* body) {
  TmaEnv env(TmaOptions{.env = EnvId::kParkour, .body = body});
  env.set_environment({{"input_vector", {-0.15, 0.8, 0.1}},
                       {"water_level", {0.5}},
                       {"creepers_width", {0.25}},
                       {"creepers_height", {2.0}},
                       {"creepers_spacing", {2.5}}});
  std::uint64_t seed = 0;
  for (auto _ : state) env.reset(seed++);
}
BENCHMARK_CAPTURE(BM_ParkourReset, old_classic_bipedal, "old_classic_bipedal")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ParkourReset, fish, "fish")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_ParkourReset, climbing_profile_chimpanzee, "climbing_profile_chimpanzee")
    ->Unit(benchmark::kMillisecond);

void BM_ParkourStep(benchmark::State& state, const char* body) {
  TmaEnv env(TmaOptions{.env = EnvId::kParkour, .body = body});
  env.set_environment({{"input_vector", {-0.15, 0.8, 0.1}}, {"water_level", {1.0}}});
  env.reset(0);
  time_random_steps(state, env);
}
BENCHMARK_CAPTURE(BM_ParkourStep, fish, "fish");

void BM_Cppn(benchmark::State& state) {
  const Cppn cppn(data_dir() / "ground_ceiling_cppn.f32", 2);
  std::vector<float> out;
  const std::array<double, 3> input = {-0.15, 0.8, 0.1};
  for (auto _ : state) cppn.generate(input, kTerrainLength, out);
}
BENCHMARK(BM_Cppn)->Unit(benchmark::kMicrosecond);

void BM_Render600x400(benchmark::State& state) {
  const auto holder = stump_env("old_classic_bipedal");
  const TmaEnv& env = *holder;
  std::vector<std::uint8_t> rgb;
  for (auto _ : state) render(env, 600, 400, true, rgb);
}
BENCHMARK(BM_Render600x400)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace cradle::tma

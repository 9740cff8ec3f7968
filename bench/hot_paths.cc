// Google Benchmark targets for the per-step hot paths: bare physics, touch, proprioception, the
// eyes and a whole env step, each on a reference config.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <vector>

#include "core/rng.h"
#include "envs/babybench.h"

namespace cradle {
namespace {

std::shared_ptr<const envs::BabyBenchAssets> assets_for(const char* name, bool vision) {
  Config config = load_config(std::filesystem::path(CRADLE_SOURCE_DIR) / "configs" / name);
  config.vision_active = vision;
  return envs::make_assets(config);
}

// A started env whose state has been moved by some random steps.
std::unique_ptr<envs::BabyBenchEnv> started(std::shared_ptr<const envs::BabyBenchAssets> assets) {
  auto env = std::make_unique<envs::BabyBenchEnv>(std::move(assets));
  env->reset(0);
  return env;
}

void BM_BarePhysicsSelfTouch(benchmark::State& state) {
  const auto assets = assets_for("config_selftouch.yml", false);
  sim::Sim sim(assets->model.get(), assets->config.actuation_model, 1);
  sim.restore(assets->settled);
  for (auto _ : state) mj_step(sim.model(), sim.data());
}
BENCHMARK(BM_BarePhysicsSelfTouch);

void BM_TouchReadSelfTouch(benchmark::State& state) {
  const auto assets = assets_for("config_selftouch.yml", false);
  sim::Sim sim(assets->model.get(), assets->config.actuation_model, 1);
  sim.restore(assets->settled);
  std::vector<float> out(assets->touch->size());
  for (auto _ : state) {
    assets->touch->read(sim.model(), sim.data(), out);
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["sensors"] = assets->touch->sensor_count();
}
BENCHMARK(BM_TouchReadSelfTouch);

void BM_EnvStep(benchmark::State& state, const char* config, bool vision) {
  auto env = started(assets_for(config, vision));
  std::vector<double> action(env->action_space().size());
  Rng rng(1);
  for (auto _ : state) {
    for (size_t k = 0; k < action.size(); ++k) {
      action[k] = rng.uniform(env->action_space().low[k], env->action_space().high[k]);
    }
    if (env->step(action).truncated) env->reset();
  }
}
BENCHMARK_CAPTURE(BM_EnvStep, self_touch, "config_selftouch.yml", false);
BENCHMARK_CAPTURE(BM_EnvStep, hand_regard, "config_handregard.yml", true);
BENCHMARK_CAPTURE(BM_EnvStep, test_installation, "config_test_installation.yml", true);

void BM_EyesHandRegard(benchmark::State& state) {
  const auto assets = assets_for("config_handregard.yml", true);
  sim::Sim sim(assets->model.get(), assets->config.actuation_model, 1);
  sim.restore(assets->settled);
  senses::Eyes eyes(sim.model(), assets->config.vision_resolution);
  const int n = eyes.space().size();
  std::vector<std::uint8_t> left(n), right(n);
  for (auto _ : state) eyes.render(sim.model(), sim.data(), left, right);
}
BENCHMARK(BM_EyesHandRegard);

}  // namespace
}  // namespace cradle

BENCHMARK_MAIN();

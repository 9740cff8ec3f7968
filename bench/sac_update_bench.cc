// Gradient steps/s of Cradle's SAC update at the self-touch sizes, for the side-by-side with
// bench/sac_update_torch.py (the same computation in Debian's python3-torch, which runs this
// benchmark too and prints the ratio measured in one go):
//   observation: the self-touch env's pooled vector (counter obs_dim), action 44,
//   actor and twin (fused) critics 256-256 ReLU, batch 256, SB3's SAC defaults.
// One gradient step = sample 256 transitions, normalise them, the temperature, critic and actor
// Adam steps and the Polyak update (OffPolicyLearner::update). The replay holds 512 random
// transitions of the real env (the update's cost does not depend on the data). Arg: LibTorch
// threads of the update.
#include <benchmark/benchmark.h>
#include <torch/torch.h>

#include <filesystem>

#include "core/config.h"
#include "learn/off_policy.h"
#include "learn/registry.h"
#include "train/babybench_vector.h"

namespace cradle::learn {
namespace {

void BM_SacGradientStep(benchmark::State& state) {
  const Config config =
      load_config(std::filesystem::path(CRADLE_SOURCE_DIR) / "configs" / "config_selftouch.yml");
  const auto env = train::make_babybench_vec_env(config, 1, 1, /*training=*/false, 0);
  const LearnerOptions options{
      .seed = 1,
      .hyperparameters = {{"learning_starts", "1000000"}, {"buffer_size", "10000"}},
      .update_threads = static_cast<int>(state.range(0))};
  auto learner = make_learner("sac", *env, options);
  // Random transitions only (learning_starts is never reached): fills the replay.
  learner->learn(512, {});
  auto& sac = dynamic_cast<OffPolicyLearner&>(*learner);
  sac.update(3);  // warm-up
  for (auto _ : state) sac.update(1);
  state.counters["gradient_steps_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["obs_dim"] = sac.observation_size();
}
BENCHMARK(BM_SacGradientStep)
    ->ArgName("threads")
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->MinTime(2.0)
    ->UseRealTime();

}  // namespace
}  // namespace cradle::learn

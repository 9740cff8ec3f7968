// Gradient steps/s of SaCCM's update (learn/meta/context_sac.h) at SaMI's two settings, for
// the side-by-side with bench/sami_update_torch.py (the same computation in PyTorch):
//   panda:  256 trajectories x 50 steps (6 training envs, obs 25, action 4)
//   mujoco: 16 trajectories x 1000 steps (4 training envs, Half-Cheetah: obs 18, action 6)
// Networks as SaMI's: actor and critics 512-512-512, LSTM 128, context 6; contrastive batch = RL
// batch. The replay holds random trajectories (the update's cost does not depend on the data).
#include <benchmark/benchmark.h>
#include <torch/torch.h>

#include "learn/meta/context_sac.h"

namespace cradle::learn::meta {
namespace {

void fill(TrajectoryReplay& replay, int per_env) {
  for (int e = 0; e < replay.envs(); ++e) {
    for (int k = 0; k < per_env; ++k) {
      const torch::Tensor o = torch::randn({replay.max_len() + 1, replay.obs_size()});
      const torch::Tensor a = torch::rand({replay.max_len(), replay.action_size()}) * 2 - 1;
      replay.begin(e, {o[0].data_ptr<float>(), static_cast<size_t>(replay.obs_size())});
      for (int t = 0; t < replay.max_len(); ++t) {
        replay.add(e, {a[t].data_ptr<float>(), static_cast<size_t>(replay.action_size())},
                   static_cast<double>(k % 7),
                   {o[t + 1].data_ptr<float>(), static_cast<size_t>(replay.obs_size())});
      }
      replay.finish(e, false);
    }
  }
}

void BM_SamiUpdate(benchmark::State& state, int envs, int batch, int horizon, int obs, int action) {
  SamiConfig config;
  config.batch_size = config.contrast_batch_size = batch;
  config.update_threads = static_cast<int>(state.range(0));
  TrajectoryReplay replay(envs, 64, horizon, obs, action);
  fill(replay, 16);
  ContextSac learner("SaCCM", obs, action, config, 0);
  Rng rng(1);
  learner.update(replay, rng);  // warm-up
  for (auto _ : state) learner.update(replay, rng);
  state.counters["gradient_steps_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

BENCHMARK_CAPTURE(BM_SamiUpdate, panda_256x50, 6, 256, 50, 25, 4)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_SamiUpdate, mujoco_16x1000, 4, 16, 1000, 18, 6)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3)
    ->UseRealTime();

}  // namespace
}  // namespace cradle::learn::meta

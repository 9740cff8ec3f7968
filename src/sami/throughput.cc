#include "sami/throughput.h"

#include <memory>
#include <span>
#include <vector>

#include "core/mj_replay.h"
#include "core/rng.h"
#include "sami/env.h"

namespace cradle::sami {
namespace {

// The env's steps and the bare replay of the controls and applied forces it wrote.
struct SamiHooks {
  SamiEnv& env;
  MjReplay& recorder;
  mjData* bare;
  const std::vector<double>& actions;  // a fixed table of random actions, cycled
  int width = 0;
  long t = 0;  // env steps so far (the table's cursor)

  void begin(long) { recorder.begin(env.model(), env.data(), bare); }
  bool step(long) {
    const size_t row = static_cast<size_t>(t++ % 64) * static_cast<size_t>(width);
    const StepResult r =
        env.step(std::span<const double>(actions).subspan(row, static_cast<size_t>(width)));
    return r.terminated || r.truncated;
  }
  void end() { recorder.end(); }
  // The episode's model (hidden parameters applied); the env resets only after this.
  void replay() { recorder.replay(env.model(), bare); }
  bool exact() {
    return recorder.complete() && MjReplay::same_state(env.model(), env.data(), bare);
  }
  void next_episode() { env.reset(); }
};

}  // namespace

Throughput measure_throughput(EnvId id, long steps, std::uint64_t seed, int blocks) {
  auto env = make_env(id, split_sets(id, Split::kTrain), seed);
  const Spec& spec = env->spec();
  const long block_steps = block_size(steps, blocks, 50);
  const std::unique_ptr<mjData, void (*)(mjData*)> bare(mj_makeData(env->shared_model()),
                                                        mj_deleteData);
  MjReplay recorder(env->shared_model(), 2 * block_steps * spec.frame_skip + 16,
                    /*applied_forces=*/true);
  Rng rng(seed + 1);
  std::vector<double> actions(64 * static_cast<size_t>(spec.action_size));
  for (double& a : actions) a = rng.uniform(spec.action_low, spec.action_high);
  env->reset(seed);
  SamiHooks hooks{.env = *env,
                  .recorder = recorder,
                  .bare = bare.get(),
                  .actions = actions,
                  .width = spec.action_size};
  Throughput out;
  out.timing = time_blocks(steps, block_steps, hooks);
  const BlockTiming& t = out.timing;
  out.env_steps_per_s = steps / t.env_s;
  out.bare_steps_per_s = steps / t.bare_s;
  out.ratio = t.ratio.median;
  out.env_us = 1e6 * t.env_s / steps;
  out.bare_us = 1e6 * t.bare_s / steps;
  return out;
}

}  // namespace cradle::sami

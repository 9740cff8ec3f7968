// Single-core throughput of a SaMI env against the bare mj_steps it contains, measured in one run
// in CPU time of the thread: alternating blocks of env steps and of bare mj_steps that replay the
// controls (and, for Panda, the applied forces) the env wrote, from the same start state on the
// same model with the episode's hidden parameters (core/replay_bench.h).
#pragma once

#include <cstdint>

#include "core/replay_bench.h"
#include "sami/task.h"

namespace cradle::sami {

struct Throughput {
  double env_steps_per_s = 0;
  double bare_steps_per_s = 0;  // env-step equivalents: frame_skip mj_steps each
  double ratio = 0;             // env time / bare time per env step: the blocks' median
  double env_us = 0;            // CPU time per env step
  double bare_us = 0;           // CPU time of its frame_skip bare mj_steps
  BlockTiming timing;           // blocks, the ratio's spread, whether the replay was exact
};

// Runs `steps` env steps with random actions (resets at the horizon, or at success for Panda) in
// about `blocks` blocks, each followed by the bare replay of its steps.
Throughput measure_throughput(EnvId id, long steps, std::uint64_t seed = 0, int blocks = 20);

}  // namespace cradle::sami

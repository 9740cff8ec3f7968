// Single-core throughput of a SaMI env against the bare mj_steps it contains, measured in one run
// with interleaved blocks so that both see the same machine load, in thread CPU time.
#pragma once

#include <cstdint>

#include "sami/task.h"

namespace cradle::sami {

struct Throughput {
  double env_steps_per_s = 0;
  double bare_steps_per_s = 0;  // env-step equivalents: frame_skip mj_steps each
  double ratio = 0;             // env time / bare time per env step (1 = no overhead)
};

// Runs `steps` env steps and as many bare blocks of frame_skip mj_steps on the shared model, with
// the same random actions and resets at the horizon (or at success for Panda).
Throughput measure_throughput(EnvId id, long steps, std::uint64_t seed = 0);

}  // namespace cradle::sami

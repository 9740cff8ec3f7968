// The fields every env-against-bare-physics bench (`cradle bench`, `tma bench`, `sami bench`)
// reports about its alternating blocks, in one order, so the three JSON reports read alike.
#pragma once

#include <nlohmann/json.hpp>

#include "core/replay_bench.h"

namespace cradle::apps {

// Appends the blocks' ratio spread, their size, the CPU time per step of both loops and whether
// the replay was exact (the median ratio is the caller's "ratio" field).
inline void add_block_timing(nlohmann::ordered_json& out, const BlockTiming& timing, double env_us,
                             double bare_us) {
  const Spread& ratio = timing.ratio;
  out["ratio_min"] = ratio.min;
  out["ratio_q1"] = ratio.q1;
  out["ratio_q3"] = ratio.q3;
  out["ratio_max"] = ratio.max;
  out["blocks"] = ratio.count;
  out["block_steps"] = timing.block_steps;
  out["env_us_per_step"] = env_us;
  out["bare_us_per_step"] = bare_us;
  out["replay_exact"] = timing.replay_exact;
}

}  // namespace cradle::apps

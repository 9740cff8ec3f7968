// `cradle tma bench`'s timing: a TeachMyAgent env against the bare b2World::Step loop that replays
// the commands the env gave Box2D (motor speeds and torques, joint limits on or off), from the
// same start state, in alternating blocks.
#pragma once

#include <cstdint>
#include <string>

#include "core/replay_bench.h"
#include "tma/tma_env.h"

namespace cradle::apps {

struct TmaBenchResult {
  double env_steps_per_s = 0, bare_steps_per_s = 0;  // per CPU second of the thread
  double ratio = 0;                                  // env / bare time: the blocks' median
  double env_us = 0, bare_us = 0;                    // CPU time per step
  double reset_ms = 0, mass = 0;
  BlockTiming timing;  // blocks, the ratio's spread, whether the replay was exact
};

// `steps` random-action steps of the embodiment on the bench's fixed task of env `id`, in about
// `blocks` blocks. The bare loop steps a second world built from the same seed, kept in the env's
// state: where the env changes the world outside Box2D's step (water, climbing), the second world
// is brought back to the env's state by replaying the episode's actions through the env (not
// timed) before the next segment, and the replay counts as inexact.
TmaBenchResult tma_bench(tma::EnvId id, const std::string& body, long steps, std::uint64_t seed,
                         int blocks = 20);

}  // namespace cradle::apps

// Env against bare physics, timed fairly on a shared machine: the env runs a short segment of
// steps while the commands it gives its physics are recorded, then the bare physics replays
// exactly those commands from the segment's start state. Segments alternate, so both loops see
// the same trajectory and nearly the same machine load; their CPU times add up into blocks of
// about `block_steps` env steps, and the blocks' env/bare ratios give a median and its spread.
#pragma once

#include <time.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace cradle {

// CPU time of the calling thread in seconds: time other processes take is not counted.
inline double thread_cpu_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// Median, quartiles and range of a sample (linear interpolation between order statistics).
struct Spread {
  double median = 0, q1 = 0, q3 = 0, min = 0, max = 0;
  int count = 0;
};

inline Spread spread(std::vector<double> values) {
  Spread s;
  s.count = static_cast<int>(values.size());
  if (values.empty()) return s;
  std::sort(values.begin(), values.end());
  const auto quantile = [&](double q) {
    const double at = q * static_cast<double>(values.size() - 1);
    const size_t lo = static_cast<size_t>(std::floor(at));
    const size_t hi = std::min(lo + 1, values.size() - 1);
    return values[lo] + (at - static_cast<double>(lo)) * (values[hi] - values[lo]);
  };
  s.median = quantile(0.5);
  s.q1 = quantile(0.25);
  s.q3 = quantile(0.75);
  s.min = values.front();
  s.max = values.back();
  return s;
}

struct BlockTiming {
  long steps = 0;            // env steps timed
  long block_steps = 0;      // env steps per block (the last block may be shorter)
  double env_s = 0;          // CPU seconds in env steps
  double bare_s = 0;         // CPU seconds replaying them on the bare physics
  Spread ratio;              // env / bare time over the blocks
  bool replay_exact = true;  // the bare state equalled the env's at the end of every segment
};

// Blocks of about steps / blocks env steps (at least min_block_steps, or all steps).
inline long block_size(long steps, int blocks, long min_block_steps) {
  const long size = (steps + blocks - 1) / blocks;
  return std::min(steps, std::max(size, min_block_steps));
}

// Times `steps` env steps in segments that end at block ends and at episode ends. The hooks:
//   begin(n)       untimed: up to n steps follow; the bare physics takes the env's state, the
//                  actions are drawn and recording starts;
//   step(i) -> bool   timed: the segment's i-th env step; true when the episode ended;
//   end()          untimed: recording stops;
//   replay()       timed: the bare physics replays the segment's recorded commands;
//   exact() -> bool   untimed: whether the bare state now equals the env's;
//   next_episode() untimed: after a segment whose episode ended (the env's reset).
template <class Hooks>
BlockTiming time_blocks(long steps, long block_steps, Hooks& hooks) {
  BlockTiming out;
  out.block_steps = block_steps;
  std::vector<double> ratios;
  double block_env = 0, block_bare = 0;
  long in_block = 0;
  while (out.steps < steps) {
    const long room = std::min(block_steps - in_block, steps - out.steps);
    hooks.begin(room);
    long n = 0;
    bool ended = false;
    const double t0 = thread_cpu_seconds();
    while (n < room && !ended) ended = hooks.step(n++);
    const double t1 = thread_cpu_seconds();
    hooks.end();
    const double t2 = thread_cpu_seconds();
    hooks.replay();
    const double t3 = thread_cpu_seconds();
    if (!hooks.exact()) out.replay_exact = false;
    if (ended) hooks.next_episode();
    block_env += t1 - t0;
    block_bare += t3 - t2;
    in_block += n;
    out.steps += n;
    if (in_block == block_steps || out.steps == steps) {
      if (block_bare > 0) ratios.push_back(block_env / block_bare);
      out.env_s += block_env;
      out.bare_s += block_bare;
      block_env = block_bare = 0;
      in_block = 0;
    }
  }
  out.ratio = spread(std::move(ratios));
  return out;
}

}  // namespace cradle

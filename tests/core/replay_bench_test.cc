// The alternating env/bare timing (core/replay_bench.h): blocks, segments ending at episode ends,
// the replay check, and the median with its spread.
#include "core/replay_bench.h"

#include <gtest/gtest.h>

#include <vector>

namespace {

using cradle::BlockTiming;

TEST(ReplayBench, SpreadGivesMedianQuartilesAndRange) {
  const cradle::Spread s = cradle::spread({5, 1, 4, 2, 3});
  EXPECT_EQ(s.count, 5);
  EXPECT_DOUBLE_EQ(s.median, 3);
  EXPECT_DOUBLE_EQ(s.q1, 2);
  EXPECT_DOUBLE_EQ(s.q3, 4);
  EXPECT_DOUBLE_EQ(s.min, 1);
  EXPECT_DOUBLE_EQ(s.max, 5);
  const cradle::Spread even = cradle::spread({4, 1, 3, 2});
  EXPECT_DOUBLE_EQ(even.median, 2.5);
  EXPECT_DOUBLE_EQ(even.q1, 1.75);
  EXPECT_EQ(cradle::spread({}).count, 0);
}

TEST(ReplayBench, BlockSizeSplitsTheStepsWithAFloor) {
  EXPECT_EQ(cradle::block_size(5000, 20, 50), 250);
  EXPECT_EQ(cradle::block_size(200, 20, 50), 50);
  EXPECT_EQ(cradle::block_size(30, 20, 50), 30);
  EXPECT_EQ(cradle::block_size(2001, 20, 50), 101);
}

// Episodes of 7 steps; records every call.
struct FakeHooks {
  std::vector<long> segments;  // steps per segment
  int replays = 0, resets = 0, in_episode = 0;
  bool exact_after = true;
  long begun = 0, last_room = 0;
  void begin(long n) {
    last_room = n;
    segments.push_back(0);
  }
  bool step(long i) {
    EXPECT_EQ(i, segments.back());
    EXPECT_LT(i, last_room);
    ++segments.back();
    volatile double sink = 0;  // some CPU time for both loops
    for (int k = 0; k < 2000; ++k) sink = sink + k;
    return ++in_episode == 7;
  }
  void end() {}
  void replay() {
    ++replays;
    volatile double sink = 0;
    for (long k = 0; k < 1000 * segments.back(); ++k) sink = sink + static_cast<double>(k);
  }
  bool exact() { return exact_after; }
  void next_episode() {
    ++resets;
    in_episode = 0;
  }
};

TEST(ReplayBench, SegmentsEndAtEpisodeAndBlockEnds) {
  FakeHooks hooks;
  const BlockTiming t = cradle::time_blocks(40, 10, hooks);
  EXPECT_EQ(t.steps, 40);
  EXPECT_EQ(t.block_steps, 10);
  EXPECT_EQ(t.ratio.count, 4);
  // Blocks of 10 steps cut at the ends of 7-step episodes: 7 3 | 4 6 | 1 7 2 | 5 5.
  EXPECT_EQ(hooks.segments, (std::vector<long>{7, 3, 4, 6, 1, 7, 2, 5, 5}));
  EXPECT_EQ(hooks.replays, static_cast<int>(hooks.segments.size()));
  EXPECT_EQ(hooks.resets, 5);
  EXPECT_TRUE(t.replay_exact);
  EXPECT_GT(t.env_s, 0);
  EXPECT_GT(t.bare_s, 0);
  EXPECT_LE(t.ratio.min, t.ratio.q1);
  EXPECT_LE(t.ratio.q1, t.ratio.median);
  EXPECT_LE(t.ratio.median, t.ratio.q3);
  EXPECT_LE(t.ratio.q3, t.ratio.max);

  FakeHooks inexact;
  inexact.exact_after = false;
  EXPECT_FALSE(cradle::time_blocks(20, 10, inexact).replay_exact);
}

}  // namespace

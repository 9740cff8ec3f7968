// `cradle tma bench`: the bare b2World::Step loop replays the env's motor commands from the same
// state (bitwise the env's world after each block on Stump Tracks), and the report has the blocks'
// median ratio and its spread; bad flags are one-line errors.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "fixture.h"

namespace {

using cradle::test::run_cradle;
using cradle::test::RunResult;

TEST(TmaBench, JsonReportsTheMedianRatioAndItsSpread) {
  const RunResult r = run_cradle(
      "tma bench --json --steps 400 --env stump-tracks --embodiment old_classic_bipedal");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.size(), 1u);
  const auto& b = j[0];
  EXPECT_EQ(b["embodiment"], "old_classic_bipedal");
  EXPECT_EQ(b["steps"], 400);
  EXPECT_EQ(b["blocks"], 8);
  EXPECT_EQ(b["block_steps"], 50);
  // A walker on Stump Tracks: the env's step is the motors and Box2D's step, nothing else.
  EXPECT_EQ(b["replay_exact"], true);
  for (const char* key :
       {"env_steps_per_s", "bare_steps_per_s", "ratio", "ratio_min", "ratio_q1", "ratio_q3",
        "ratio_max", "env_us_per_step", "bare_us_per_step", "reset_ms"}) {
    EXPECT_GT(b[key].get<double>(), 0) << key;
  }
  EXPECT_LE(b["ratio_min"].get<double>(), b["ratio"].get<double>());
  EXPECT_LE(b["ratio"].get<double>(), b["ratio_max"].get<double>());
}

TEST(TmaBench, BadFlagsAreOneLineErrors) {
  for (const char* args : {"tma bench --steps 5", "tma bench --env nowhere",
                           "tma bench --embodiment nope", "tma bench --steps many"}) {
    const RunResult r = run_cradle(args);
    EXPECT_EQ(r.status, 1) << args;
    EXPECT_EQ(r.out.rfind("cradle: error: ", 0), 0u) << args << ": " << r.out;
    EXPECT_EQ(r.out.find('\n'), r.out.size() - 1) << args << ": " << r.out;
  }
}

}  // namespace

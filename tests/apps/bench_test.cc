// `cradle bench`'s bare loop: the controls a BabyBench env writes into MuJoCo, replayed on a bare
// mjData from the env's start state, end in the env's physics state bit for bit; the report has
// the blocks' median ratio and its spread.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/mj_replay.h"
#include "core/rng.h"
#include "envs/babybench.h"
#include "fixture.h"

namespace {

TEST(BenchReplay, BareLoopEndsInTheEnvsStateBitwise) {
  const auto assets =
      cradle::envs::make_assets(cradle::test::reference_config("config_selftouch.yml"));
  cradle::envs::BabyBenchEnv env(assets, 0);
  env.reset(7);
  const mjModel* m = env.model();
  mjData* bare = mj_makeData(m);
  constexpr int kSteps = 60;
  cradle::MjReplay recorder(m, kSteps * 4, /*applied_forces=*/false);
  cradle::Rng rng(3);
  const cradle::Box& space = env.action_space();
  std::vector<double> action(space.size());
  for (int segment = 0; segment < 2; ++segment) {
    recorder.begin(m, env.data(), bare);
    for (int i = 0; i < kSteps; ++i) {
      for (size_t k = 0; k < action.size(); ++k)
        action[k] = rng.uniform(space.low[k], space.high[k]);
      env.step(action);
    }
    recorder.end();
    EXPECT_EQ(recorder.substeps(), kSteps * assets->config.frame_skip);
    EXPECT_TRUE(recorder.complete());
    EXPECT_FALSE(cradle::MjReplay::same_state(m, env.data(), bare));  // not replayed yet
    recorder.replay(m, bare);
    EXPECT_TRUE(cradle::MjReplay::same_state(m, env.data(), bare)) << "segment " << segment;
  }
  // Nothing is recorded once the segment ended.
  env.step(action);
  EXPECT_EQ(recorder.substeps(), kSteps * assets->config.frame_skip);
  mj_deleteData(bare);
}

TEST(BenchReplay, JsonReportsTheMedianRatioAndItsSpread) {
  const auto r =
      cradle::test::run_cradle("bench --json --steps 200 --config " +
                               cradle::test::config_path("config_selftouch.yml").string());
  ASSERT_EQ(r.status, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["blocks"], 4);
  EXPECT_EQ(j["block_steps"], 50);
  EXPECT_EQ(j["replay_exact"], true);
  const double lo = j["ratio_min"], q1 = j["ratio_q1"], median = j["ratio"], q3 = j["ratio_q3"],
               hi = j["ratio_max"];
  EXPECT_GT(lo, 0);
  EXPECT_LE(lo, q1);
  EXPECT_LE(q1, median);
  EXPECT_LE(median, q3);
  EXPECT_LE(q3, hi);
  EXPECT_GT(j["env_us_per_step"].get<double>(), 0);
  EXPECT_GT(j["bare_us_per_step"].get<double>(), 0);
}

}  // namespace

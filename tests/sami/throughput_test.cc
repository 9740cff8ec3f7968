// `cradle sami bench`'s bare loop: the controls (and Panda's applied forces) a SaMI env writes
// into MuJoCo, replayed on a bare mjData of the episode's model from the env's start state, end in
// the env's physics state bit for bit; the throughput has the blocks' median and spread.
#include "sami/throughput.h"

#include <gtest/gtest.h>

#include <memory>
#include <nlohmann/json.hpp>
#include <vector>

#include "core/mj_replay.h"
#include "core/rng.h"
#include "fixture.h"
#include "sami/env.h"

namespace cradle::sami {
namespace {

// Runs `steps` random steps of a fresh env recorded, replays them, and says whether the bare data
// ends in the env's state.
bool replay_ends_in_env_state(EnvId id, int steps, bool applied_forces) {
  auto env = make_env(id, split_sets(id, Split::kExtreme), 5);
  env->reset(11);
  std::unique_ptr<mjData, void (*)(mjData*)> bare(mj_makeData(env->shared_model()), mj_deleteData);
  MjReplay recorder(env->shared_model(), steps * env->spec().frame_skip, applied_forces);
  Rng rng(2);
  std::vector<double> action(env->spec().action_size);
  recorder.begin(env->model(), env->data(), bare.get());
  for (int i = 0; i < steps; ++i) {
    for (double& a : action) a = rng.uniform(-1, 1);
    env->step(action);
  }
  recorder.end();
  EXPECT_TRUE(recorder.complete());
  EXPECT_EQ(recorder.substeps(), steps * env->spec().frame_skip);
  recorder.replay(env->model(), bare.get());
  return MjReplay::same_state(env->model(), env->data(), bare.get());
}

TEST(SamiThroughput, ReplayOfAHiddenParameterEpisodeIsBitwise) {
  // Crippled, masked legs and scaled masses: the bare loop steps the episode's own model.
  EXPECT_TRUE(replay_ends_in_env_state(EnvId::kCrippleAnt, 40, true));
}

TEST(SamiThroughput, PandaReplaysTheIkControlsAndAppliedForces) {
  EXPECT_TRUE(replay_ends_in_env_state(EnvId::kPandaPush, 20, true));
  // The gravity compensation Panda applies is part of what the bare loop must replay.
  EXPECT_FALSE(replay_ends_in_env_state(EnvId::kPandaPush, 20, false));
}

TEST(SamiThroughput, ReportsTheMedianRatioAndItsSpread) {
  const Throughput t = measure_throughput(EnvId::kHalfCheetah, 400, 0, 4);
  EXPECT_EQ(t.timing.steps, 400);
  EXPECT_EQ(t.timing.block_steps, 100);
  EXPECT_EQ(t.timing.ratio.count, 4);
  EXPECT_TRUE(t.timing.replay_exact);
  EXPECT_EQ(t.ratio, t.timing.ratio.median);
  EXPECT_GT(t.timing.ratio.min, 0);
  EXPECT_LE(t.timing.ratio.min, t.ratio);
  EXPECT_LE(t.ratio, t.timing.ratio.max);
  EXPECT_GT(t.env_us, 0);
  EXPECT_GT(t.bare_us, 0);
  // Panda's episodes end at success or after 50 steps: segments end there, blocks do not.
  const Throughput panda = measure_throughput(EnvId::kPandaPush, 200, 0, 2);
  EXPECT_EQ(panda.timing.ratio.count, 2);
  EXPECT_TRUE(panda.timing.replay_exact);
}

TEST(SamiThroughput, BenchJsonHasTheSpread) {
  const test::RunResult r = test::run_cradle("sami bench --env Hopper --steps 200 --json");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.size(), 1u);
  for (const char* key : {"env_steps_per_s", "bare_steps_per_s", "ratio", "ratio_min", "ratio_q1",
                          "ratio_q3", "ratio_max", "env_us_per_step", "bare_us_per_step"}) {
    EXPECT_GT(j[0][key].get<double>(), 0) << key;
  }
  EXPECT_EQ(j[0]["env"], "Hopper");
  EXPECT_EQ(j[0]["blocks"], 4);
  EXPECT_EQ(j[0]["replay_exact"], true);
}

TEST(SamiThroughput, BenchBadFlagsAreOneLineErrors) {
  for (const char* args :
       {"sami bench --steps 5", "sami bench --env Nope", "sami bench --steps x"}) {
    const test::RunResult r = test::run_cradle(args);
    EXPECT_EQ(r.status, 1) << args;
    EXPECT_EQ(r.out.rfind("cradle: error: ", 0), 0u) << args << ": " << r.out;
    EXPECT_EQ(r.out.find('\n'), r.out.size() - 1) << args << ": " << r.out;
  }
}

}  // namespace
}  // namespace cradle::sami

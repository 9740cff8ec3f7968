// The one evaluation rollout (train/episodes.h): whole episodes per seed, the returns the env
// paid, the task's flags at the end, the same results for the same seeds.
#include "train/episodes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/error.h"
#include "envs/registry.h"

namespace cradle::train {
namespace {

// A fixed gait: every joint pushed forward.
EpisodePolicy constant(double value, int* episodes = nullptr) {
  return {.act = [value](const envs::ObservationBuffers&,
                         std::span<double> action) { std::ranges::fill(action, value); },
          .new_episode =
              [episodes] {
                if (episodes) ++*episodes;
              }};
}

TEST(RunEpisodes, PlaysWholeEpisodesAndRecordsWhatTheEnvPaid) {
  auto env = envs::make_env("tma/stump-tracks:old_classic_bipedal", 0);
  const std::vector<std::uint64_t> seeds = {3, 4, 3};
  int started = 0;
  double paid = 0;
  std::vector<int> lengths(3, 0);
  const auto results = run_episodes(*env, constant(0.3, &started), seeds, 0,
                                    [&](int episode, const envs::Env&, const envs::StepResult& s) {
                                      paid += s.reward;
                                      ++lengths[episode];
                                    });
  ASSERT_EQ(results.size(), 3u);
  EXPECT_EQ(started, 3);
  double total = 0;
  for (int e = 0; e < 3; ++e) {
    EXPECT_EQ(results[e].length, lengths[e]);
    EXPECT_EQ(results[e].seed, seeds[e]);
    total += results[e].episode_return;
  }
  EXPECT_DOUBLE_EQ(total, paid);
  // The same seed, the same episode.
  EXPECT_EQ(results[0].episode_return, results[2].episode_return);
  EXPECT_EQ(results[0].length, results[2].length);
  const auto json = episodes_json(results);
  EXPECT_NEAR(json["mean_return"].get<double>(), total / 3, 1e-9);
  EXPECT_EQ(json["episodes"].size(), 3u);
}

TEST(RunEpisodes, StopsAtMaxStepsAsTruncated) {
  auto env = envs::make_env("sami/HalfCheetah", 0);
  const std::vector<std::uint64_t> seeds = {1, 2};
  const auto results = run_episodes(*env, constant(0.0), seeds, 25);
  for (const EpisodeOutcome& r : results) {
    EXPECT_EQ(r.length, 25);
    EXPECT_TRUE(r.truncated);
    EXPECT_FALSE(r.success);
  }
  EXPECT_EQ(episodes_json(results)["success_rate"], 0.0);
}

// A fixed length runs on past the env's own end (BabyBench's evaluation of a duration): the
// episode is exactly max_steps steps; without it the same episode stops where the env ends it.
TEST(RunEpisodes, AFixedLengthRunsOnPastTheEnvsEnd) {
  auto env = envs::make_env("mimo/standup", 0);  // truncates at 500 steps
  const std::vector<std::uint64_t> seeds = {5};
  EXPECT_EQ(run_episodes(*env, constant(0.0), seeds, 600)[0].length, 500);
  int steps = 0;
  const auto fixed = run_episodes(
      *env, constant(0.0), seeds, 600,
      [&](int, const envs::Env&, const envs::StepResult&) { ++steps; }, nullptr,
      /*fixed_length=*/true);
  EXPECT_EQ(fixed[0].length, 600);
  EXPECT_EQ(steps, 600);
  EXPECT_THROW(run_episodes(*env, constant(0.0), seeds, 0, nullptr, nullptr, true), UserError);
}

// Episodes without seeds go on with the env's own stream: after a seeded reset they repeat what a
// second run from the same seed plays, and differ from one another.
TEST(RunEpisodes, UnseededEpisodesGoOnWithTheEnvsStream) {
  auto play = [] {
    auto env = envs::make_env("tma/stump-tracks:old_classic_bipedal", 0);
    env->reset(7);
    return run_episodes(*env, constant(0.3), 2);
  };
  const auto a = play(), b = play();
  ASSERT_EQ(a.size(), 2u);
  for (int e = 0; e < 2; ++e) {
    EXPECT_EQ(a[e].episode_return, b[e].episode_return);
    EXPECT_EQ(a[e].seed, 0u);
  }
  EXPECT_NE(a[0].episode_return, a[1].episode_return);
}

}  // namespace
}  // namespace cradle::train

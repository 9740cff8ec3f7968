// The cradle::envs::Env adapter: spaces, observation copy and the success / failure flags.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/rng.h"
#include "envs/tma/tma_env.h"

namespace cradle::envs {
namespace {

TEST(TmaAdapter, SpacesObservationAndFailure) {
  TmaEnvAdapter env(tma::TmaOptions{.env = tma::EnvId::kStumpTracks, .body = "spider"});
  ASSERT_EQ(env.observation_space().entries.size(), 1u);
  EXPECT_EQ(env.observation_space().entries[0].second.size(), 42);
  EXPECT_EQ(env.action_space().size(), 12);
  EXPECT_EQ(env.action_space().low[0], -1.0);
  env.reset(1);
  const auto obs = env.observation().f32(0);
  ASSERT_EQ(obs.size(), 42u);
  EXPECT_EQ(obs[0], static_cast<float>(env.env().observation()[0]));
  // Folding every joint drops the spider's body on the ground: a fatal hull contact (-100).
  std::vector<double> fold(12, -1.0);
  StepResult r;
  for (int t = 0; t < 300 && !r.terminated; ++t) r = env.step(fold);
  EXPECT_TRUE(r.terminated);
  EXPECT_EQ(r.reward, -100.0);
  EXPECT_TRUE(env.info().flag(env.info().find("is_failure")));
  EXPECT_FALSE(env.info().flag(env.info().find("is_success")));
  EXPECT_EQ(env.observation().f32(0)[1], static_cast<float>(env.env().observation()[1]));
}

// The observation is float32, as the reference's observation space: the env's float64 values
// rounded once, at reset and at every step, in both envs.
TEST(TmaAdapter, ObservationIsFloat32OfTheFloat64Values) {
  for (const auto& [id, body] : {std::pair{tma::EnvId::kStumpTracks, "old_classic_bipedal"},
                                 std::pair{tma::EnvId::kParkour, "climbing_profile_chimpanzee"}}) {
    TmaEnvAdapter env(tma::TmaOptions{.env = id, .body = body});
    ASSERT_EQ(env.observation_space().entries[0].second.dtype, DType::kFloat32);
    env.reset(5);
    Rng rng(6);
    std::vector<double> action(env.action_space().size());
    int rounded = 0;
    for (int t = 0; t <= 60; ++t) {
      const std::span<const double> wide = env.env().observation();
      const std::span<const float> obs = env.observation().f32(0);
      ASSERT_EQ(obs.size(), wide.size());
      for (size_t i = 0; i < obs.size(); ++i) {
        ASSERT_EQ(obs[i], static_cast<float>(wide[i])) << body << " step " << t << " [" << i << "]";
        rounded += static_cast<double>(obs[i]) != wide[i];
      }
      for (double& a : action) a = rng.uniform(-1, 1);
      if (env.step(action).terminated) env.reset();
    }
    EXPECT_GT(rounded, 0) << body;  // the float64 values are not all float32 already
  }
}

// A teacher's task arrives as reset options, one per dimension (vector parameters as name_<i>).
TEST(TmaAdapter, TakesTaskParametersAsResetOptions) {
  TmaEnvAdapter stumps(tma::TmaOptions{.env = tma::EnvId::kStumpTracks});
  stumps.set_reset_options({{"stump_height", 2.5}, {"obstacle_spacing", 1.5}});
  EXPECT_EQ(stumps.env().stump_task().stump_height, 2.5);
  EXPECT_EQ(stumps.env().stump_task().obstacle_spacing, 1.5);
  EXPECT_THROW(stumps.set_reset_options({{"stump_heigth", 1}}), UserError);
  EXPECT_THROW(stumps.set_reset_options({{"stump_height", 20}}), UserError);

  TmaEnvAdapter parkour(tma::TmaOptions{.env = tma::EnvId::kParkour});
  parkour.set_reset_options({{"input_vector_0", -0.2},
                             {"input_vector_1", 0.7},
                             {"input_vector_2", 0.1},
                             {"water_level", 0.4}});
  EXPECT_EQ(parkour.env().parkour_task().input_vector[1], 0.7);
  EXPECT_EQ(parkour.env().parkour_task().water_level, 0.4);
  // A missing index, or a vector parameter given as a scalar.
  EXPECT_THROW(parkour.set_reset_options({{"input_vector_0", 0}, {"input_vector_2", 0}}),
               UserError);
  EXPECT_THROW(parkour.set_reset_options({{"input_vector", 0}}), UserError);
}

// NaN and infinite actions are refused with the shared one-line error, before any physics.
TEST(TmaAdapter, NonFiniteActionsAreRefused) {
  TmaEnvAdapter env(tma::TmaOptions{.env = tma::EnvId::kStumpTracks, .body = "spider"});
  env.reset(2);
  const std::vector<float> before(env.observation().f32(0).begin(), env.observation().f32(0).end());
  for (double bad : {std::nan(""), double{INFINITY}, -double{INFINITY}}) {
    std::vector<double> action(12, 0.0);
    action[5] = bad;
    try {
      env.step(action);
      FAIL() << "no error for " << bad;
    } catch (const UserError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find("action 5"), std::string::npos) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  }
  EXPECT_EQ(env.env().episode_steps(), 0);
  const auto after = env.observation().f32(0);
  EXPECT_TRUE(std::equal(before.begin(), before.end(), after.begin()));
}

}  // namespace
}  // namespace cradle::envs

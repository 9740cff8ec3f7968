// The thin adapter to today's envs::Env interface.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/error.h"
#include "envs/sami/sami_env.h"

namespace cradle::envs {
namespace {

TEST(SamiAdapter, ForwardsSpacesObservationsAndSuccess) {
  auto env = make_sami_env("PandaPush", "train", 0);
  const DictSpace& space = env->observation_space();
  ASSERT_EQ(space.entries.size(), 3u);
  EXPECT_EQ(space.entries[0].first, "observation");
  EXPECT_EQ(space.entries[0].second.dtype, DType::kFloat32);
  EXPECT_EQ(env->action_space().size(), 4);
  env->reset(1);
  auto& adapter = static_cast<SamiEnvAdapter&>(*env);
  const auto family = adapter.sami().observation();
  for (int i = 0; i < 19; ++i) EXPECT_FLOAT_EQ(env->observation().f32(0)[i], family[i]);
  const std::vector<double> action(4, 0.0);
  const StepResult r = env->step(action);
  EXPECT_EQ(env->info().steps, 1);
  EXPECT_EQ(env->info().flag(env->info().find("is_success")), r.terminated);
  for (int i = 0; i < 3; ++i) {
    EXPECT_FLOAT_EQ(env->observation().f32(2)[i], adapter.sami().observation()[22 + i]);
  }

  auto cheetah = make_sami_env("HalfCheetah", "moderate", 0);
  cheetah->reset(2);
  EXPECT_EQ(cheetah->observation_space().entries[0].second.dtype, DType::kFloat32);
  EXPECT_EQ(cheetah->observation().f32(0).size(), 18u);
}

// Every SaMI env publishes float32 observations, as the reference's gym envs: the values are the
// env's double computation rounded once, and the adapter passes them on bit for bit.
TEST(SamiObservations, AreTheDoubleComputationRoundedToFloat32) {
  for (sami::EnvId id : sami::all_envs()) {
    const std::string name(sami::env_name(id));
    SCOPED_TRACE(name);
    const std::string split = id == sami::EnvId::kCrippleHopper ? "extreme" : "train";
    SamiEnvAdapter adapter(sami::make_env(name, split, 5));
    EXPECT_EQ(adapter.sami().spec().obs_dtype, DType::kFloat32);
    for (const auto& entry : adapter.observation_space().entries) {
      EXPECT_EQ(entry.second.dtype, DType::kFloat32) << entry.first;
    }
    adapter.reset(9);
    std::vector<double> action(adapter.action_space().size());
    int rounded = 0;  // values that float32 cannot hold exactly
    for (int t = 0; t < 5; ++t) {
      for (size_t i = 0; i < action.size(); ++i) action[i] = std::sin(0.7 * t + i);
      adapter.step(action);
      const auto exact = adapter.sami().observation_f64();
      const auto published = adapter.sami().observation();
      ASSERT_EQ(exact.size(), published.size());
      for (size_t i = 0; i < exact.size(); ++i) {
        EXPECT_EQ(published[i], static_cast<float>(exact[i])) << i;
        rounded += static_cast<double>(published[i]) != exact[i];
      }
      const auto& keys = adapter.sami().spec().keys;
      for (size_t k = 0; k < keys.size(); ++k) {
        const auto buffer = adapter.observation().f32(static_cast<int>(k));
        for (int i = 0; i < keys[k].size; ++i) {
          EXPECT_EQ(buffer[i], published[keys[k].offset + i]);
        }
      }
    }
    // The physics ran in double: most values lose digits in the rounding.
    EXPECT_GT(rounded, 0);
  }
}

// NaN and infinite actions are refused with the shared one-line error before any physics, for a
// locomotion and a Panda env.
TEST(SamiAdapter, NonFiniteActionsAreRefused) {
  for (const char* name : {"HalfCheetah", "PandaPush"}) {
    SCOPED_TRACE(name);
    auto env = make_sami_env(name, name[0] == 'P' ? "train" : "moderate", 0);
    env->reset(3);
    for (double bad : {std::nan(""), double{INFINITY}, -double{INFINITY}}) {
      std::vector<double> action(env->action_space().size(), 0.0);
      action.back() = bad;
      try {
        env->step(action);
        FAIL() << "no error for " << bad;
      } catch (const UserError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find("action " + std::to_string(action.size() - 1)), std::string::npos)
            << message;
        EXPECT_EQ(message.find('\n'), std::string::npos) << message;
      }
    }
    EXPECT_EQ(static_cast<SamiEnvAdapter&>(*env).sami().info().steps, 0);
  }
}

}  // namespace
}  // namespace cradle::envs

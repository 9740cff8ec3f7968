// Vector over task sets (one sub-env per set, one shared model) and rendering.
#include "sami/vector.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <span>
#include <vector>

#include "core/error.h"
#include "sami/render.h"

namespace cradle::sami {
namespace {

bool contains(const std::vector<double>& values, double v) {
  return std::find(values.begin(), values.end(), v) != values.end();
}

TEST(SamiVector, OneSubEnvPerTaskSetOnOneSharedModel) {
  const std::vector<TaskSet> sets = split_sets(EnvId::kHalfCheetah, Split::kModerate);
  SamiVector vec(EnvId::kHalfCheetah, sets, 1, 2);
  ASSERT_EQ(vec.size(), 4);
  vec.reset(10);
  std::vector<double> actions(vec.size() * vec.spec().action_size, 0.3);
  for (int t = 0; t < 3; ++t) vec.step(actions);
  for (int i = 0; i < vec.size(); ++i) {
    EXPECT_EQ(vec.env(i).shared_model(), vec.env(0).shared_model());
    EXPECT_NE(vec.env(i).data(), vec.env(0).data() + (i == 0 ? 1 : 0));
    // Each sub-env draws only from its own set.
    EXPECT_TRUE(contains(sets[i].mass, vec.env(i).info().mass));
    EXPECT_TRUE(contains(sets[i].damping, vec.env(i).info().damping));
  }
  EXPECT_THROW(vec.step(std::vector<double>(5)), UserError);
  // The vector's rows are the sub-envs' float32 observations, unchanged.
  const std::span<const float> rows = vec.observations();
  const int obs = vec.spec().obs_size;
  for (int i = 0; i < vec.size(); ++i) {
    const auto own = vec.env(i).observation();
    EXPECT_TRUE(std::equal(own.begin(), own.end(), rows.begin() + i * obs)) << i;
  }
}

TEST(SamiVector, AutoResetKeepsTheFinalObservationAndIsThreadCountInvariant) {
  auto run = [](int threads) {
    SamiVector vec(EnvId::kCrippleHopper, split_sets(EnvId::kCrippleHopper, Split::kModerate), 4,
                   threads);
    vec.reset(3);
    std::vector<double> actions(vec.size() * 3, -0.2), trace;
    int finished = 0;
    for (int t = 0; t < 1000; ++t) {
      vec.step(actions);
      for (int i = 0; i < vec.size(); ++i) {
        trace.push_back(vec.rewards()[i]);
        if (vec.truncated()[i]) {
          ++finished;
          // The final observation is the ended episode's last (float32) one, not the reset's.
          EXPECT_EQ(vec.final_observation(i).size(), 11u);
          EXPECT_NE(vec.final_observation(i)[0], vec.env(i).observation()[0]);
          EXPECT_EQ(vec.final_info(i).steps, 1000);
          EXPECT_EQ(vec.env(i).info().steps, 0);  // already reset
        }
      }
    }
    EXPECT_EQ(finished, vec.size());
    trace.insert(trace.end(), vec.observations().begin(), vec.observations().end());
    return trace;
  };
  EXPECT_EQ(run(1), run(2));
}

TEST(SamiRender, CrippledLegShowsRed) {
  auto count_red = [](std::vector<TaskSet> sets) {
    auto env = make_env(EnvId::kCrippleAnt, std::move(sets), 0);
    env->reset(0);
    Renderer renderer(*env, 160, 120);
    std::vector<std::uint8_t> rgb(160 * 120 * 3);
    renderer.render(*env, rgb);
    int red = 0;
    for (size_t p = 0; p < rgb.size(); p += 3) red += rgb[p] > 120 && rgb[p + 1] < 60;
    return red;
  };
  EXPECT_GT(count_red({{.cripple = {{0}}}}), 20);
  EXPECT_EQ(count_red({{}}), 0);
}

}  // namespace
}  // namespace cradle::sami

// Covar-GMM: after fitting, sampling concentrates where the return rises over time.
#include <gtest/gtest.h>

#include "core/error.h"
#include "teach/teacher.h"

namespace cradle::teach {
namespace {

// Left half x < 0.5: the return climbs through each batch of 100 episodes (positive time-return
// covariance); right half: always 10 (no progress).
double rising_return(const Task& t, int episode) {
  return t[0] < 0.5f ? 100.0 * (episode % 100) / 100.0 : 10.0;
}

TEST(CovarGmm, SamplingConcentratesWhereReturnsRise) {
  CovarGmmParams p;
  p.fit_rate = 100;
  p.potential_ks = {2, 3, 4};
  p.random_task_ratio = 0.1;
  auto t = make_covar_gmm_teacher({0.f, 0.f}, {1.f, 1.f}, 5, p);
  EXPECT_FALSE(t->is_non_exploratory_task_sampling_available());
  for (int n = 0; n < 600; ++n) {
    const Task x = t->sample_task();
    t->episodic_update(x, rising_return(x, n), false);
  }
  EXPECT_TRUE(t->is_non_exploratory_task_sampling_available());
  const auto dump = t->dump();
  EXPECT_EQ(dump.at("fits").get<int>(), 6);
  EXPECT_EQ(dump.at("gmms").size(), 6u);
  // Uniform sampling would put 1000 +- 22 of 2000 tasks left; following the covariance, far more.
  int left = 0;
  for (int n = 0; n < 2000; ++n) {
    const Task x = t->sample_task();
    ASSERT_TRUE(x[0] >= 0.f && x[0] <= 1.f && x[1] >= 0.f && x[1] <= 1.f);
    left += x[0] < 0.5f;
  }
  EXPECT_GT(left, 1300);
}

TEST(CovarGmm, BootstrapsFromTheInitialDistribution) {
  CovarGmmParams p;
  p.initial_dist = DiagGaussian{{0.9f, 0.9f}, {0.0001f, 0.0001f}};
  auto t = make_covar_gmm_teacher({0.f, 0.f}, {1.f, 1.f}, 3, p);
  for (int n = 0; n < 50; ++n) {
    const Task x = t->sample_task();
    EXPECT_NEAR(x[0], 0.9f, 0.05f);
    EXPECT_NEAR(x[1], 0.9f, 0.05f);
  }
  EXPECT_EQ(t->dump().at("task_origins").size(), 0u);  // nothing played yet
}

TEST(CovarGmm, RejectsBadParameters) {
  CovarGmmParams p;
  p.fit_rate = 1;
  EXPECT_THROW(make_covar_gmm_teacher({0.f}, {1.f}, 0, p), UserError);
  p = {};
  p.potential_ks = {0};
  EXPECT_THROW(make_covar_gmm_teacher({0.f}, {1.f}, 0, p), UserError);
  p = {};
  p.initial_dist = DiagGaussian{{0.f, 0.f}, {1.f, 1.f}};  // 2 values for a 1-D space
  EXPECT_THROW(make_covar_gmm_teacher({0.f}, {1.f}, 0, p), UserError);
}

}  // namespace
}  // namespace cradle::teach

// ALP-GMM: after fitting, sampling concentrates where absolute learning progress is non-zero.
#include <gtest/gtest.h>

#include "core/error.h"
#include "teach/teacher.h"

namespace cradle::teach {
namespace {

// Left half x < 0.5: the return flips between 0 and 50 from episode to episode (ALP > 0);
// right half: always 10 (ALP = 0).
double synthetic_return(const Task& t, int episode) {
  return t[0] < 0.5f ? 50.0 * ((episode * 7919) % 2) : 10.0;
}

TEST(AlpGmm, SamplingConcentratesWhereProgressIsNonZero) {
  AlpGmmParams p;
  p.fit_rate = 150;
  p.potential_ks = {2, 3, 4, 5};
  auto t = make_alp_gmm_teacher({0.f, 0.f}, {1.f, 1.f}, 11, p);
  EXPECT_FALSE(t->is_non_exploratory_task_sampling_available());
  // Bootstrap is uniform: about half the tasks fall left.
  int left = 0;
  for (int n = 0; n < 150; ++n) {
    const Task x = t->sample_task();
    left += x[0] < 0.5f;
    t->episodic_update(x, synthetic_return(x, n), false);
  }
  EXPECT_NEAR(left, 75, 25);
  EXPECT_TRUE(t->is_non_exploratory_task_sampling_available());
  for (int n = 150; n < 900; ++n) {
    const Task x = t->sample_task();
    t->episodic_update(x, synthetic_return(x, n), false);
  }
  EXPECT_EQ(t->dump().at("fits").get<int>(), 6);
  // Uniform sampling would put 1000 +- 22 of 2000 tasks left; following ALP puts far more.
  left = 0;
  for (int n = 0; n < 2000; ++n) {
    const Task x = t->sample_task();
    ASSERT_GE(x[1], 0.f);
    ASSERT_LE(x[1], 1.f);
    left += x[0] < 0.5f;
  }
  EXPECT_GT(left, 1300);
}

TEST(AlpGmm, RejectsBadParameters) {
  AlpGmmParams p;
  p.criterion = "aicc2";
  EXPECT_THROW(make_alp_gmm_teacher({0.f}, {1.f}, 0, p), UserError);
  p = {};
  p.potential_ks = {};
  EXPECT_THROW(make_alp_gmm_teacher({0.f}, {1.f}, 0, p), UserError);
  p = {};
  p.random_task_ratio = -0.1;
  EXPECT_THROW(make_alp_gmm_teacher({0.f}, {1.f}, 0, p), UserError);
}

}  // namespace
}  // namespace cradle::teach

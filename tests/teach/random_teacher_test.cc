// Random teacher: uniform coverage of the box, determinism, bound checks.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "core/error.h"
#include "teach/teacher.h"

namespace cradle::teach {
namespace {

// Chi-square over a 5x5 grid: 25 cells, 24 dof, 99.9 % quantile is about 51.2.
TEST(RandomTeacher, CoversTheBoxUniformly) {
  auto teacher = make_random_teacher({-1.f, 10.f}, {3.f, 12.f}, 7);
  constexpr int kBins = 5, kDraws = 25000;
  std::vector<int> counts(kBins * kBins, 0);
  for (int n = 0; n < kDraws; ++n) {
    const Task t = teacher->sample_task();
    ASSERT_EQ(t.size(), 2u);
    ASSERT_GE(t[0], -1.f);
    ASSERT_LE(t[0], 3.f);
    ASSERT_GE(t[1], 10.f);
    ASSERT_LE(t[1], 12.f);
    const int i = std::min(kBins - 1, static_cast<int>((t[0] + 1.f) / 4.f * kBins));
    const int j = std::min(kBins - 1, static_cast<int>((t[1] - 10.f) / 2.f * kBins));
    ++counts[i * kBins + j];
  }
  const double expected = static_cast<double>(kDraws) / (kBins * kBins);
  double chi2 = 0;
  for (int c : counts) chi2 += (c - expected) * (c - expected) / expected;
  EXPECT_LT(chi2, 51.2);
}

TEST(RandomTeacher, SameSeedSameTasks) {
  auto a = make_random_teacher({0.f}, {1.f}, 3), b = make_random_teacher({0.f}, {1.f}, 3);
  auto c = make_random_teacher({0.f}, {1.f}, 4);
  bool differs = false;
  for (int n = 0; n < 20; ++n) {
    const Task ta = a->sample_task(), tb = b->sample_task(), tc = c->sample_task();
    EXPECT_EQ(ta, tb);
    differs |= ta != tc;
  }
  EXPECT_TRUE(differs);
}

TEST(RandomTeacher, RejectsBadBounds) {
  EXPECT_THROW(make_random_teacher({}, {}, 0), UserError);
  EXPECT_THROW(make_random_teacher({0.f, 0.f}, {1.f}, 0), UserError);
  EXPECT_THROW(make_random_teacher({2.f}, {1.f}, 0), UserError);
}

TEST(RandomTeacher, DumpNamesItselfAndItsBounds) {
  auto teacher = make_random_teacher({0.f, -2.f}, {1.f, 2.f}, 0);
  const nlohmann::json j = teacher->dump();
  EXPECT_EQ(j.at("teacher"), "random");
  EXPECT_EQ(j.at("maxs")[1].get<float>(), 2.f);
}

}  // namespace
}  // namespace cradle::teach

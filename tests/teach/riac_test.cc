// RIAC: splits where learning progress differs, keeps leaves within max_region_size, samples by
// ALP.
#include <gtest/gtest.h>

#include <vector>

#include "core/error.h"
#include "teach/teacher.h"

namespace cradle::teach {
namespace {

// Left half [0, 0.5): the return climbs with time (progress); right half: a constant return.
double synthetic_return(const Task& t, int episode) { return t[0] < 0.5f ? episode * 0.1 : 5.0; }

TEST(Riac, SplitsWhereProgressDiffersAndKeepsRegionSize) {
  RiacParams p;
  p.max_region_size = 40;
  auto t = make_riac_teacher({0.f, 0.f}, {1.f, 1.f}, 5, p);
  for (int n = 0; n < 1500; ++n) {
    const Task x = t->sample_task();
    t->episodic_update(x, synthetic_return(x, n), false);
  }
  const nlohmann::json j = t->dump();
  const auto& regions = j.at("regions");
  ASSERT_GT(regions.size(), 1u);
  // Leaves hold at most maxlen pairs, inner nodes maxlen + 1; every region is wide enough.
  for (const auto& r : regions) {
    const std::size_t cap = r.at("leaf").get<bool>() ? 40u : 41u;
    EXPECT_LE(r.at("size").get<std::size_t>(), cap);
    for (int i = 0; i < 2; ++i)
      EXPECT_GE(r.at("hi")[i].get<float>() - r.at("lo")[i].get<float>(), 1.f / 6.f - 1e-6f);
  }
  // Sampling now favours the half where the return still moves.
  int left = 0;
  for (int n = 0; n < 2000; ++n) left += t->sample_task()[0] < 0.5f;
  EXPECT_GT(left, 1200);
}

TEST(Riac, NoSplitWithoutDataAndUniformAtFirst) {
  auto t = make_riac_teacher({-1.f}, {1.f}, 0);
  for (int n = 0; n < 100; ++n) {
    const Task x = t->sample_task();
    ASSERT_GE(x[0], -1.f);
    ASSERT_LE(x[0], 1.f);
    t->episodic_update(x, 1.0, true);
  }
  EXPECT_EQ(t->dump().at("regions").size(), 1u);  // 100 < 200 pairs
}

TEST(Riac, RejectsBadParameters) {
  RiacParams p;
  p.max_region_size = 1;
  EXPECT_THROW(make_riac_teacher({0.f}, {1.f}, 0, p), UserError);
  p = {};
  p.discard_ratio = 2;
  EXPECT_THROW(make_riac_teacher({0.f}, {1.f}, 0, p), UserError);
}

}  // namespace
}  // namespace cradle::teach

// ADR: the box grows after high returns at its bounds, shrinks after low ones, stays in the limits.
#include <gtest/gtest.h>

#include <vector>

#include "core/error.h"
#include "teach/teacher.h"

namespace cradle::teach {
namespace {

std::vector<float> box_of(const Teacher& t, const char* key) {
  return t.dump().at(key).get<std::vector<float>>();
}

TEST(Adr, ExpandsAfterSuccessesAndStaysInTheLimits) {
  AdrParams p;
  p.initial_point = {0.5f};
  p.boundary_prob = 1.0;  // every sample pins a bound
  auto t = make_adr_teacher({0.f}, {1.f}, 1, p);
  // The first full queue (10 returns of 200 >= 180) moves both bounds of the point by 0.1.
  for (int n = 0; n < 10; ++n) t->episodic_update(t->sample_task(), 200.0, true);
  EXPECT_FLOAT_EQ(box_of(*t, "cur_min")[0], 0.4f);
  EXPECT_FLOAT_EQ(box_of(*t, "cur_max")[0], 0.6f);
  // Many more successes reach the global limits and no further.
  for (int n = 0; n < 400; ++n) t->episodic_update(t->sample_task(), 200.0, true);
  EXPECT_FLOAT_EQ(box_of(*t, "cur_min")[0], 0.f);
  EXPECT_FLOAT_EQ(box_of(*t, "cur_max")[0], 1.f);
  EXPECT_GE(t->dump().at("bound_changes").size(), 10u);
}

TEST(Adr, ShrinksAfterFailures) {
  AdrParams p;
  p.initial_point = {0.5f};
  p.boundary_prob = 1.0;
  auto t = make_adr_teacher({0.f}, {1.f}, 2, p);
  // Grow the box part-way (bounds at the global limits are never pinned, so stop before).
  for (int n = 0; n < 40; ++n) t->episodic_update(t->sample_task(), 200.0, true);
  const float width = box_of(*t, "cur_max")[0] - box_of(*t, "cur_min")[0];
  ASSERT_GT(width, 0.3f);
  ASSERT_LT(width, 0.95f);
  // Returns of -5 (<= 0) pull the bounds back in, never crossing each other.
  for (int n = 0; n < 100; ++n) t->episodic_update(t->sample_task(), -5.0, false);
  const float lo = box_of(*t, "cur_min")[0], hi = box_of(*t, "cur_max")[0];
  EXPECT_LT(hi - lo, width - 0.15f);
  EXPECT_LE(lo, hi);
}

TEST(Adr, MiddlingReturnsLeaveTheBoxAlone) {
  AdrParams p;
  p.initial_point = {0.5f, 0.5f};
  auto t = make_adr_teacher({0.f, 0.f}, {1.f, 1.f}, 3, p);
  for (int n = 0; n < 100; ++n) {
    const Task x = t->sample_task();
    EXPECT_EQ(x, (Task{0.5f, 0.5f}));
    t->episodic_update(x, 90.0, false);
  }
  EXPECT_TRUE(t->dump().at("bound_changes").empty());
}

TEST(Adr, RejectsBadParameters) {
  AdrParams p;
  p.initial_point = {2.f};
  EXPECT_THROW(make_adr_teacher({0.f}, {1.f}, 0, p), UserError);
  p = {};
  p.boundary_prob = 1.5;
  EXPECT_THROW(make_adr_teacher({0.f}, {1.f}, 0, p), UserError);
  p = {};
  p.step_size = 0.f;
  EXPECT_THROW(make_adr_teacher({0.f}, {1.f}, 0, p), UserError);
}

}  // namespace
}  // namespace cradle::teach

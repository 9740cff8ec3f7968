// Setter-Solver: the judge learns the feasibility of a known split; goals stay in the box.
#include <gtest/gtest.h>

#include "core/error.h"
#include "teach/teacher.h"

namespace cradle::teach {
namespace {

TEST(SetterSolver, JudgePredictsTheFeasibilityOfAKnownSplit) {
  SetterSolverParams p;
  p.update_frequency = 25;
  p.setter_hidden_size = 32;
  p.lr = 1e-2;
  auto t = make_setter_solver_teacher({0.f, -1.f}, {1.f, 1.f}, 9, p);
  // Solvable exactly when x < 0.5.
  int solved = 0;
  for (int e = 0; e < 1000; ++e) {
    const Task x = t->sample_task();
    ASSERT_TRUE(x[0] >= 0.f && x[0] <= 1.f && x[1] >= -1.f && x[1] <= 1.f);
    solved += x[0] < 0.5f;
    t->episodic_update(x, 0.0, x[0] < 0.5f);
  }
  ASSERT_GT(solved, 50);
  ASSERT_LT(solved, 950);
  const auto updates = t->dump().at("updates");
  ASSERT_EQ(updates.size(), 40u);
  // Accuracy on each new batch (before the judge sees it): high once it has learnt the split.
  double late = 0;
  for (int i = 30; i < 40; ++i) late += updates[i].at("judge_accuracy").get<double>() / 10;
  EXPECT_GT(late, 0.9);
  EXPECT_LT(updates[39].at("judge_loss").get<double>(), updates[0].at("judge_loss").get<double>());
}

TEST(SetterSolver, RejectsBadParameters) {
  SetterSolverParams p;
  p.update_frequency = 0;
  EXPECT_THROW(make_setter_solver_teacher({0.f}, {1.f}, 0, p), UserError);
  p = {};
  p.setter_hidden_size = 0;
  EXPECT_THROW(make_setter_solver_teacher({0.f}, {1.f}, 0, p), UserError);
  // 1-D spaces work (couplings with nothing to move are left out).
  auto t = make_setter_solver_teacher({2.f}, {3.f}, 0, {});
  const Task x = t->sample_task();
  EXPECT_TRUE(x[0] >= 2.f && x[0] <= 3.f);
}

}  // namespace
}  // namespace cradle::teach

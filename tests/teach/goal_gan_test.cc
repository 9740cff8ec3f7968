// GoalGAN: labels goals of intermediate difficulty and learns to generate inside them.
#include <gtest/gtest.h>

#include "core/error.h"
#include "teach/teacher.h"

namespace cradle::teach {
namespace {

// Over x: below 0.3 always solved, 0.3..0.6 solved every other try (rate 0.5 over 2 rollouts),
// above 0.6 never.
bool solved(const Task& t, int episode) {
  if (t[0] < 0.3f) return true;
  return t[0] < 0.6f && episode % 2 == 0;
}

TEST(GoalGan, LabelsIntermediateGoalsAndGeneratesInsideThem) {
  GoalGanParams p;
  p.state_noise_level = 0.1;
  p.update_size = 40;
  p.train_iterations = 100;
  p.use_pretrained_samples = true;  // on the easy corner
  p.initial_dist = DiagGaussian{{0.15f, 0.5f}, {0.01f, 0.04f}};
  p.pretrain_iterations = 200;
  auto t = make_goal_gan_teacher({0.f, 0.f}, {1.f, 1.f}, 3, p);
  // Pretrained on the easy corner: generated goals sit mostly below x = 0.3.
  int easy = 0;
  for (int n = 0; n < 200; ++n) easy += t->non_exploratory_task_sampling()[0] < 0.3f;
  EXPECT_GT(easy, 120);
  for (int e = 0; e < 800; ++e) {
    const Task x = t->sample_task();
    ASSERT_TRUE(x[0] >= 0.f && x[0] <= 1.f && x[1] >= 0.f && x[1] <= 1.f);
    t->episodic_update(x, 0.0, solved(x, e));
  }
  const auto dump = t->dump();
  // Labels: exactly the goals in the band, whose success rate is 0.5, are positive.
  int positives = 0;
  for (const auto& g : dump.at("labelled_goals")) {
    const float x = g.at("goal").at(0).get<float>();
    const bool in_band = x >= 0.3f && x < 0.6f;
    EXPECT_EQ(g.at("label").get<bool>(), in_band) << x;
    positives += in_band;
  }
  EXPECT_GT(positives, 10);
  EXPECT_GE(dump.at("trainings").size(), 3u);
  EXPECT_GT(dump.at("success_buffer").get<int>(), 0);
  // After training, most generated goals fall in the band (30 % of the box).
  int in_band = 0;
  for (int n = 0; n < 200; ++n) {
    const float x = t->non_exploratory_task_sampling()[0];
    in_band += x >= 0.3f && x < 0.6f;
  }
  EXPECT_GT(in_band, 100);
}

TEST(GoalGan, RejectsBadParameters) {
  GoalGanParams p;
  p.goid_lb = 0.8;
  EXPECT_THROW(make_goal_gan_teacher({0.f}, {1.f}, 0, p), UserError);
  p = {};
  p.n_rollouts = 0;
  EXPECT_THROW(make_goal_gan_teacher({0.f}, {1.f}, 0, p), UserError);
}

}  // namespace
}  // namespace cradle::teach

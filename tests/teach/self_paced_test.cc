// SPDL: the task distribution moves toward the target once the student's value is positive, stays
// put when it is zero, and needs the student's value estimator.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <vector>

#include "core/error.h"
#include "teach/teacher.h"

namespace cradle::teach {
namespace {

SelfPacedParams params() {
  SelfPacedParams p;
  p.update_frequency = 500;  // every 50 episodes of 10 steps
  p.update_offset = 0;
  p.zeta = 0.5;
  p.initial_dist = DiagGaussian{{0.2f, 0.2f}, {0.01f, 0.01f}};  // near a corner of [0, 1]^2
  return p;
}

// Plays `episodes` episodes of 10 steps whose initial state is the task itself.
void play(Teacher& t, int episodes) {
  for (int e = 0; e < episodes; ++e) {
    const Task task = t.sample_task();
    t.record_initial_state(task, task);
    for (int s = 0; s < 10; ++s) t.step_update(task, {0.f}, 1.0, task, s == 9);
  }
}

double kl_of(const Teacher& t, int i) {
  return t.dump().at("history").at(i).at("kl").get<double>();
}

TEST(SelfPaced, MovesTowardTheTargetAsTheValueRises) {
  auto t = make_self_paced_teacher({0.f, 0.f}, {1.f, 1.f}, 4, params());
  // The student's value rises toward the centre of the box (the target's mean).
  t->set_value_estimator([](const std::vector<std::vector<float>>& s) {
    std::vector<float> v;
    for (const auto& x : s) v.push_back(10.f * (1.f - std::hypot(x[0] - 0.5f, x[1] - 0.5f)));
    return v;
  });
  play(*t, 1000);  // 20 updates
  const auto dump = t->dump();
  ASSERT_EQ(dump.at("iterations").get<int>(), 20);
  const auto& history = dump.at("history");
  ASSERT_EQ(history.size(), 21u);
  // KL to the target (centre, std 0.25) ends far below where it began.
  EXPECT_GT(kl_of(*t, 0), 2.0);
  EXPECT_LT(kl_of(*t, 10), 0.5 * kl_of(*t, 0));
  EXPECT_LT(kl_of(*t, 20), 0.01);
  EXPECT_GT(history.back().at("alpha").get<double>(), 0.0);
  // The mean has reached the centre.
  const auto mean = history.back().at("mean").get<std::vector<double>>();
  EXPECT_NEAR(mean[0], 0.5, 0.05);
  EXPECT_NEAR(mean[1], 0.5, 0.05);
}

// KL(p || q) of two Gaussians given as mean and column-major covariance (as dumped).
double kl(const nlohmann::json& p, const nlohmann::json& q) {
  const auto pm = p.at("mean").get<std::vector<double>>(),
             qm = q.at("mean").get<std::vector<double>>();
  const auto pc = p.at("covariance").get<std::vector<double>>();
  const auto qc = q.at("covariance").get<std::vector<double>>();
  const int d = static_cast<int>(pm.size());
  const Eigen::MatrixXd sp = Eigen::Map<const Eigen::MatrixXd>(pc.data(), d, d);
  const Eigen::MatrixXd sq = Eigen::Map<const Eigen::MatrixXd>(qc.data(), d, d);
  const Eigen::VectorXd dm = Eigen::Map<const Eigen::VectorXd>(qm.data(), d) -
                             Eigen::Map<const Eigen::VectorXd>(pm.data(), d);
  const Eigen::MatrixXd sq_inv = sq.inverse();
  return 0.5 * ((sq_inv * sp).trace() + dm.dot(sq_inv * dm) - d +
                std::log(sq.determinant() / sp.determinant()));
}

TEST(SelfPaced, EveryStepStaysInTheTrustRegion) {
  SelfPacedParams p = params();
  p.max_kl = 0.05;
  auto t = make_self_paced_teacher({0.f, 0.f}, {1.f, 1.f}, 6, p);
  t->set_value_estimator([](const std::vector<std::vector<float>>& s) {
    std::vector<float> v;
    for (const auto& x : s) v.push_back(10.f * x[0]);
    return v;
  });
  play(*t, 500);  // 10 updates
  const auto history = t->dump().at("history");
  ASSERT_EQ(history.size(), 11u);
  int moved = 0;
  for (int i = 1; i < 11; ++i) {
    const double step = kl(history[i - 1], history[i]);
    EXPECT_LE(step, 1.5 * 0.05 + 1e-6) << i;
    moved += step > 1e-4;
  }
  EXPECT_GE(moved, 5);
}

TEST(SelfPaced, StaysWhileTheValueIsZero) {
  auto t = make_self_paced_teacher({0.f, 0.f}, {1.f, 1.f}, 4, params());
  t->set_value_estimator(
      [](const std::vector<std::vector<float>>& s) { return std::vector<float>(s.size(), 0.f); });
  play(*t, 100);
  const auto history = t->dump().at("history");
  ASSERT_EQ(history.size(), 3u);
  EXPECT_EQ(history.back().at("mean"), history.front().at("mean"));
  EXPECT_DOUBLE_EQ(history.back().at("alpha").get<double>(), 0.0);
}

TEST(SelfPaced, NeedsTheValueEstimatorAndSamplesInTheBox) {
  auto t = make_self_paced_teacher({0.f, 0.f}, {1.f, 1.f}, 4, params());
  for (int n = 0; n < 100; ++n) {
    const Task x = t->sample_task();
    ASSERT_TRUE(x[0] >= 0.f && x[0] <= 1.f && x[1] >= 0.f && x[1] <= 1.f);
  }
  EXPECT_THROW(play(*t, 50), UserError);
  SelfPacedParams p = params();
  p.max_kl = 0;
  EXPECT_THROW(make_self_paced_teacher({0.f, 0.f}, {1.f, 1.f}, 4, p), UserError);
}

}  // namespace
}  // namespace cradle::teach

// GMM: EM recovers a known 2-component mixture and BIC/AIC pick k = 2.
#include "teach/gmm.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"

namespace cradle::teach {
namespace {

// 200 points around (0, 0) with std 0.5, 400 around (5, 5) with std (1, 0.3).
Eigen::MatrixXd two_blobs(Rng& rng) {
  Eigen::MatrixXd x(600, 2);
  for (int i = 0; i < 600; ++i) {
    if (i < 200) {
      x.row(i) << 0.5 * standard_normal(rng), 0.5 * standard_normal(rng);
    } else {
      x.row(i) << 5 + standard_normal(rng), 5 + 0.3 * standard_normal(rng);
    }
  }
  return x;
}

TEST(Gmm, RecoversTwoComponentsAndPicksKTwo) {
  Rng data_rng(1), fit_rng(2);
  const Eigen::MatrixXd x = two_blobs(data_rng);
  for (const char* criterion : {"bic", "aic"}) {
    const Gmm g = fit_best_gmm(x, {1, 2, 3, 4}, criterion, fit_rng);
    ASSERT_EQ(g.k(), 2) << criterion;
    const int big = g.means[0][0] > g.means[1][0] ? 0 : 1;
    EXPECT_NEAR(g.weights[big], 2.0 / 3.0, 0.03);
    EXPECT_NEAR(g.means[big][0], 5.0, 0.2);
    EXPECT_NEAR(g.means[big][1], 5.0, 0.1);
    EXPECT_NEAR(g.means[1 - big].norm(), 0.0, 0.15);
    EXPECT_NEAR(std::sqrt(g.covs[big](0, 0)), 1.0, 0.15);
    EXPECT_NEAR(std::sqrt(g.covs[big](1, 1)), 0.3, 0.05);
  }
}

TEST(Gmm, SamplesFollowTheComponent) {
  Rng rng(3);
  Gmm g;
  g.weights = {1.0};
  g.means = {Eigen::Vector2d(1, -2)};
  Eigen::MatrixXd cov(2, 2);
  cov << 4, 1, 1, 1;
  g.covs = {cov};
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  double cross = 0;
  constexpr int kDraws = 20000;
  for (int n = 0; n < kDraws; ++n) {
    const Eigen::VectorXd s = sample_component(g, 0, rng);
    sum += s;
    cross += (s[0] - 1) * (s[1] + 2);
  }
  EXPECT_NEAR(sum[0] / kDraws, 1.0, 0.05);
  EXPECT_NEAR(sum[1] / kDraws, -2.0, 0.05);
  EXPECT_NEAR(cross / kDraws, 1.0, 0.1);
}

TEST(Gmm, RejectsBadInput) {
  Rng rng(0);
  const Eigen::MatrixXd x = Eigen::MatrixXd::Zero(3, 2);
  EXPECT_THROW(fit_gmm(x, 4, rng), UserError);
  EXPECT_THROW(fit_best_gmm(x, {1}, "aicc2", rng), UserError);
}

}  // namespace
}  // namespace cradle::teach

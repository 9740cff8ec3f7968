// EM for full-covariance Gaussian mixtures: k-means initialisation, log-domain responsibilities.
#include "teach/gmm.h"

#include <cmath>
#include <limits>
#include <numbers>
#include <string>
#include <utility>

#include "core/error.h"

namespace cradle::teach {
namespace {

// log N(x | mean, cov) for every row, through one Cholesky factor.
Eigen::VectorXd log_density(const Eigen::MatrixXd& x, const Eigen::VectorXd& mean,
                            const Eigen::MatrixXd& cov) {
  const Eigen::LLT<Eigen::MatrixXd> llt(cov);
  const Eigen::MatrixXd l = llt.matrixL();
  const double log_det = 2.0 * l.diagonal().array().log().sum();
  const Eigen::MatrixXd centred = (x.rowwise() - mean.transpose()).transpose();
  const Eigen::MatrixXd z = llt.matrixL().solve(centred);
  const double d = static_cast<double>(x.cols());
  return (-0.5 * (z.colwise().squaredNorm().array() + log_det + d * std::log(2 * std::numbers::pi)))
      .matrix()
      .transpose();
}

// Hard assignments from a few Lloyd iterations started at k distinct random rows.
std::vector<int> kmeans(const Eigen::MatrixXd& x, int k, Rng& rng) {
  const int n = static_cast<int>(x.rows());
  std::vector<int> order(n);
  for (int i = 0; i < n; ++i) order[i] = i;
  for (int i = 0; i < k; ++i)
    std::swap(order[i], order[i + static_cast<int>(rng.uniform() * (n - i))]);
  Eigen::MatrixXd centres(k, x.cols());
  for (int j = 0; j < k; ++j) centres.row(j) = x.row(order[j]);
  std::vector<int> label(n, 0);
  for (int iter = 0; iter < 30; ++iter) {
    for (int i = 0; i < n; ++i)
      (centres.rowwise() - x.row(i)).rowwise().squaredNorm().minCoeff(&label[i]);
    Eigen::MatrixXd sum = Eigen::MatrixXd::Zero(k, x.cols());
    Eigen::VectorXd count = Eigen::VectorXd::Zero(k);
    for (int i = 0; i < n; ++i) {
      sum.row(label[i]) += x.row(i);
      count[label[i]] += 1;
    }
    for (int j = 0; j < k; ++j)
      if (count[j] > 0) centres.row(j) = sum.row(j) / count[j];
  }
  return label;
}

// M step: weights, means, covariances from responsibilities r (n x k).
void m_step(const Eigen::MatrixXd& x, const Eigen::MatrixXd& r, double reg, Gmm& g) {
  const int n = static_cast<int>(x.rows()), d = static_cast<int>(x.cols());
  for (int j = 0; j < g.k(); ++j) {
    const double nk = r.col(j).sum() + 10 * std::numeric_limits<double>::epsilon();
    g.weights[j] = nk / n;
    g.means[j] = (x.transpose() * r.col(j)) / nk;
    const Eigen::MatrixXd c = x.rowwise() - g.means[j].transpose();
    g.covs[j] =
        (c.transpose() * r.col(j).asDiagonal() * c) / nk + reg * Eigen::MatrixXd::Identity(d, d);
  }
}

}  // namespace

bool usable(const Gmm& gmm) {
  if (gmm.k() == 0 || !std::isfinite(gmm.aic) || !std::isfinite(gmm.bic)) return false;
  for (int j = 0; j < gmm.k(); ++j) {
    if (!std::isfinite(gmm.weights[j]) || !gmm.means[j].allFinite() || !gmm.covs[j].allFinite())
      return false;
    if (Eigen::LLT<Eigen::MatrixXd>(gmm.covs[j]).info() != Eigen::Success) return false;
  }
  return true;
}

double standard_normal(Rng& rng) {
  const double u1 = 1.0 - rng.uniform(), u2 = rng.uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

Gmm fit_gmm(const Eigen::MatrixXd& x, int k, Rng& rng, const GmmOptions& options) {
  const int n = static_cast<int>(x.rows()), d = static_cast<int>(x.cols());
  if (k < 1) throw UserError("gmm: k must be >= 1");
  if (n < k)
    throw UserError("gmm: " + std::to_string(n) + " points for k = " + std::to_string(k) +
                    "; expected at least k points");
  if (!x.allFinite()) throw UserError("gmm: the points hold a non-finite value; expected finite");
  Gmm g;
  g.weights.assign(k, 1.0 / k);
  g.means.assign(k, Eigen::VectorXd::Zero(d));
  g.covs.assign(k, Eigen::MatrixXd::Identity(d, d));
  // Start from the k-means partition (sklearn's default initialisation).
  Eigen::MatrixXd r = Eigen::MatrixXd::Zero(n, k);
  const std::vector<int> label = kmeans(x, k, rng);
  for (int i = 0; i < n; ++i) r(i, label[i]) = 1;
  m_step(x, r, options.reg, g);
  // Alternate E and M steps until the mean log-likelihood gains less than tol.
  double previous = -std::numeric_limits<double>::infinity(), total = 0;
  Eigen::MatrixXd logp(n, k);
  for (int iter = 0; iter < options.max_iter; ++iter) {
    for (int j = 0; j < k; ++j)
      logp.col(j) = log_density(x, g.means[j], g.covs[j]).array() + std::log(g.weights[j]);
    const Eigen::VectorXd top = logp.rowwise().maxCoeff();
    const Eigen::VectorXd lse =
        top.array() + (logp.colwise() - top).array().exp().rowwise().sum().log();
    total = lse.sum();
    r = (logp.colwise() - lse).array().exp();
    if (std::abs(total / n - previous) < options.tol) break;
    previous = total / n;
    m_step(x, r, options.reg, g);
  }
  g.log_likelihood = total;
  g.n_params = k * (d + d * (d + 1) / 2) + k - 1;
  g.aic = -2 * total + 2 * g.n_params;
  g.bic = -2 * total + g.n_params * std::log(static_cast<double>(n));
  return g;
}

Gmm fit_best_gmm(const Eigen::MatrixXd& x, const std::vector<int>& ks, const std::string& criterion,
                 Rng& rng, const GmmOptions& options) {
  if (criterion != "aic" && criterion != "bic")
    throw UserError("gmm: criterion '" + criterion + "'; expected aic or bic");
  if (ks.empty()) throw UserError("gmm: no candidate k; expected at least one");
  Gmm best;
  double best_score = std::numeric_limits<double>::infinity();
  for (int k : ks) {
    Gmm g = fit_gmm(x, k, rng, options);
    const double score = criterion == "aic" ? g.aic : g.bic;
    // A fit whose covariances lost positive definiteness (points far apart in scale) is no
    // candidate: sampling from it would give NaN tasks.
    if (!usable(g)) continue;
    if (score < best_score) {
      best_score = score;
      best = std::move(g);
    }
  }
  return best;
}

Eigen::VectorXd sample_component(const Gmm& gmm, int j, Rng& rng) {
  Eigen::VectorXd z(gmm.means[j].size());
  for (int i = 0; i < z.size(); ++i) z[i] = standard_normal(rng);
  return gmm.means[j] + Eigen::LLT<Eigen::MatrixXd>(gmm.covs[j]).matrixL() * z;
}

}  // namespace cradle::teach

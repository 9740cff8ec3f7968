// Gaussian mixtures with full covariances, fitted by EM (k-means start), chosen by AIC or BIC.
// Written once for the GMM teachers (ALP-GMM, Covar-GMM).
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

#include "core/rng.h"

namespace cradle::teach {

struct Gmm {
  std::vector<double> weights;
  std::vector<Eigen::VectorXd> means;
  std::vector<Eigen::MatrixXd> covs;
  double log_likelihood = 0;  // total over the fitted points
  int n_params = 0;           // k * (d + d(d+1)/2) + k - 1
  double aic = 0, bic = 0;
  int k() const { return static_cast<int>(weights.size()); }
};

struct GmmOptions {
  int max_iter = 100;  // sklearn defaults
  double tol = 1e-3;   // on the mean per-point log-likelihood
  double reg = 1e-6;   // added to every covariance diagonal
};

// Fits k components to the rows of x. Throws UserError when k < 1 or x has fewer than k rows.
Gmm fit_gmm(const Eigen::MatrixXd& x, int k, Rng& rng, const GmmOptions& options = {});
// Fits every k of ks and keeps the lowest criterion ("aic" or "bic"; else UserError) among the
// usable fits; a Gmm with no component when none is.
Gmm fit_best_gmm(const Eigen::MatrixXd& x, const std::vector<int>& ks, const std::string& criterion,
                 Rng& rng, const GmmOptions& options = {});
// True when the mixture has components, finite scores, weights and means, and positive-definite
// covariances (so that sample_component gives finite draws).
bool usable(const Gmm& gmm);
// One draw from component j.
Eigen::VectorXd sample_component(const Gmm& gmm, int j, Rng& rng);
// Standard normal (Box-Muller).
double standard_normal(Rng& rng);

}  // namespace cradle::teach

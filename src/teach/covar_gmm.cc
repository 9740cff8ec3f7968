// Covar-GMM: every fit_rate episodes, GMMs on the last fit_rate [task, relative time, return]
// vectors; a component whose time-return covariance is positive (the return rises over the batch)
// shows learning progress and is drawn in proportion to it.
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "core/error.h"
#include "teach/gmm_teacher.h"

namespace cradle::teach {
namespace {

class CovarGmmTeacher final : public GmmTeacher {
 public:
  CovarGmmTeacher(std::vector<float> mins, std::vector<float> maxs, std::uint64_t seed,
                  CovarGmmParams p)
      : GmmTeacher(std::move(mins), std::move(maxs), seed, "covar_gmm",
                   {p.fit_rate, p.potential_ks, p.random_task_ratio, p.initial_dist}),
        absolute_lp_(p.absolute_lp) {}

  void episodic_update(const Task& task, double ret, bool) override {
    check_episode(task, ret);
    // [task, index within the batch / fit_rate, return].
    const int in_batch = static_cast<int>(rows_.size() % static_cast<std::size_t>(fit_rate()));
    std::vector<double> row(task.begin(), task.end());
    row.push_back(static_cast<double>(in_batch) / fit_rate());
    row.push_back(ret);
    rows_.push_back(std::move(row));
    // Refit on the last fit_rate vectors every fit_rate episodes.
    if (record_episode()) {
      Eigen::MatrixXd x(fit_rate(), dims() + 2);
      const std::size_t start = rows_.size() - fit_rate();
      for (int r = 0; r < fit_rate(); ++r)
        for (int c = 0; c < dims() + 2; ++c) x(r, c) = rows_[start + r][c];
      if (!refit(x, "aic")) return;  // the previous mixture and its progress stay
      lps_.assign(gmm().k(), 0.0);
      for (int j = 0; j < gmm().k(); ++j) {
        const double cov_tr = gmm().covs[j](dims(), dims() + 1);
        lps_[j] = absolute_lp_ ? std::abs(cov_tr) : std::max(0.0, cov_tr);
      }
      fit_episodes_.push_back(static_cast<int>(rows_.size()));
      record_fit();
    }
  }

  nlohmann::json dump() const override {
    nlohmann::json j = GmmTeacher::dump();
    j["fit_episodes"] = fit_episodes_;
    j["gmms"] = fits_;  // per fit: weights, means, covariances, learning progress
    return j;
  }
  const char* name() const override { return "covar_gmm"; }

 private:
  // The component's time-return covariance (positive part, or absolute value).
  double progress(int c) const override { return lps_[c]; }
  // Book-keeping of the fit just made.
  void record_fit() {
    nlohmann::json fit = {{"weights", gmm().weights}, {"lp", lps_}};
    for (int j = 0; j < gmm().k(); ++j) {
      const Eigen::VectorXd& m = gmm().means[j];
      const Eigen::MatrixXd& c = gmm().covs[j];
      fit["means"].push_back(std::vector<double>(m.data(), m.data() + m.size()));
      fit["covariances"].push_back(std::vector<double>(c.data(), c.data() + c.size()));
    }
    fits_.push_back(std::move(fit));
  }

  bool absolute_lp_;
  std::vector<std::vector<double>> rows_;
  std::vector<double> lps_;
  std::vector<int> fit_episodes_;
  nlohmann::json fits_ = nlohmann::json::array();
};

}  // namespace

std::unique_ptr<Teacher> make_covar_gmm_teacher(std::vector<float> mins, std::vector<float> maxs,
                                                std::uint64_t seed, CovarGmmParams params) {
  return std::make_unique<CovarGmmTeacher>(std::move(mins), std::move(maxs), seed,
                                           std::move(params));
}

}  // namespace cradle::teach

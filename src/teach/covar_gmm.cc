// Covar-GMM: every fit_rate episodes, GMMs on the last fit_rate [task, relative time, return]
// vectors; a component whose time-return covariance is positive (the return rises over the batch)
// shows learning progress and is drawn in proportion to it.
#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "core/error.h"
#include "teach/gmm.h"
#include "teach/teacher.h"

namespace cradle::teach {
namespace {

class CovarGmmTeacher final : public Teacher {
 public:
  CovarGmmTeacher(std::vector<float> mins, std::vector<float> maxs, std::uint64_t seed,
                  CovarGmmParams p)
      : Teacher(std::move(mins), std::move(maxs), seed), p_(std::move(p)), fit_rng_(seed + 1) {
    // Check the parameters before anything depends on them.
    if (p_.fit_rate < 2) throw UserError("covar_gmm: fit_rate must be >= 2");
    if (p_.potential_ks.empty()) throw UserError("covar_gmm: potential_ks is empty");
    for (int k : p_.potential_ks)
      if (k < 1 || k > p_.fit_rate)
        throw UserError("covar_gmm: potential k " + std::to_string(k) + "; expected 1..fit_rate");
    if (!(p_.random_task_ratio >= 0 && p_.random_task_ratio <= 1))
      throw UserError("covar_gmm: random_task_ratio must lie in [0, 1]");
    if (p_.initial_dist) check_dist(*p_.initial_dist, "covar_gmm: initial_dist");
  }

  bool is_non_exploratory_task_sampling_available() const override { return fitted_; }

  Task sample_task() override {
    // Bootstrap under high expert knowledge: the env's easy region (origin -2).
    if (!fitted_ && p_.initial_dist) {
      last_origin_ = -2;
      return gaussian_task(*p_.initial_dist);
    }
    // Bootstrap and a random_task_ratio share: uniform (origin -1).
    if (!fitted_ || rng_.uniform() < p_.random_task_ratio) {
      last_origin_ = -1;
      return uniform_task();
    }
    return from_component(pick_component());
  }

  Task non_exploratory_task_sampling() override {
    if (!fitted_) return uniform_task();
    return from_component(pick_component());
  }

  void episodic_update(const Task& task, double ret, bool) override {
    // [task, index within the batch / fit_rate, return].
    const int in_batch = static_cast<int>(rows_.size() % static_cast<std::size_t>(p_.fit_rate));
    std::vector<double> row(task.begin(), task.end());
    row.push_back(static_cast<double>(in_batch) / p_.fit_rate);
    row.push_back(ret);
    rows_.push_back(std::move(row));
    origins_.push_back(last_origin_);
    // Refit on the last fit_rate vectors every fit_rate episodes.
    if (rows_.size() % static_cast<std::size_t>(p_.fit_rate) == 0) {
      Eigen::MatrixXd x(p_.fit_rate, dims() + 2);
      const std::size_t start = rows_.size() - p_.fit_rate;
      for (int r = 0; r < p_.fit_rate; ++r)
        for (int c = 0; c < dims() + 2; ++c) x(r, c) = rows_[start + r][c];
      gmm_ = fit_best_gmm(x, p_.potential_ks, "aic", fit_rng_);
      lps_.assign(gmm_.k(), 0.0);
      for (int j = 0; j < gmm_.k(); ++j) {
        const double cov_tr = gmm_.covs[j](dims(), dims() + 1);
        lps_[j] = p_.absolute_lp ? std::abs(cov_tr) : std::max(0.0, cov_tr);
      }
      fitted_ = true;
      fit_episodes_.push_back(static_cast<int>(rows_.size()));
      record_fit();
    }
  }

  nlohmann::json dump() const override {
    nlohmann::json j = Teacher::dump();
    j["episodes"] = rows_.size();
    j["fits"] = fit_episodes_.size();
    j["fit_episodes"] = fit_episodes_;
    j["task_origins"] = origins_;  // -2 initial dist, -1 random, j component index
    j["gmms"] = fits_;             // per fit: weights, means, covariances, learning progress
    return j;
  }
  const char* name() const override { return "covar_gmm"; }

 private:
  // Component index with probability proportional to its learning progress (uniform when 0).
  int pick_component() {
    double total = 0;
    for (double lp : lps_) total += lp;
    if (total <= 0) return std::min(gmm_.k() - 1, static_cast<int>(rng_.uniform() * gmm_.k()));
    double u = rng_.uniform() * total;
    for (int c = 0; c < gmm_.k(); ++c) {
      u -= lps_[c];
      if (u < 0) return c;
    }
    return gmm_.k() - 1;
  }
  // A draw from component c with the time and return coordinates dropped, clipped to the box.
  Task from_component(int c) {
    last_origin_ = c;
    const Eigen::VectorXd s = sample_component(gmm_, c, rng_);
    Task task(dims());
    for (int i = 0; i < dims(); ++i) task[i] = static_cast<float>(s[i]);
    clip(task);
    return task;
  }
  // Book-keeping of the fit just made.
  void record_fit() {
    nlohmann::json fit = {{"weights", gmm_.weights}, {"lp", lps_}};
    for (int j = 0; j < gmm_.k(); ++j) {
      const Eigen::VectorXd& m = gmm_.means[j];
      const Eigen::MatrixXd& c = gmm_.covs[j];
      fit["means"].push_back(std::vector<double>(m.data(), m.data() + m.size()));
      fit["covariances"].push_back(std::vector<double>(c.data(), c.data() + c.size()));
    }
    fits_.push_back(std::move(fit));
  }

  CovarGmmParams p_;
  Rng fit_rng_;
  std::vector<std::vector<double>> rows_;
  std::vector<int> origins_;
  int last_origin_ = -1;
  Gmm gmm_;
  std::vector<double> lps_;
  bool fitted_ = false;
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

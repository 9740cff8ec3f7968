// ALP-GMM: each episode's ALP is |return - return of the nearest earlier task|; every fit_rate
// episodes, GMMs on the last fit_rate [task, ALP] vectors are refitted, and a component is drawn
// with probability proportional to its mean ALP.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "core/error.h"
#include "teach/gmm.h"
#include "teach/teacher.h"

namespace cradle::teach {
namespace {

class AlpGmmTeacher final : public Teacher {
 public:
  AlpGmmTeacher(std::vector<float> mins, std::vector<float> maxs, std::uint64_t seed,
                AlpGmmParams p)
      : Teacher(std::move(mins), std::move(maxs), seed), p_(std::move(p)), fit_rng_(seed + 1) {
    // Check the parameters before anything depends on them.
    if (p_.fit_rate < 2) throw UserError("alp_gmm: fit_rate must be >= 2");
    if (p_.potential_ks.empty()) throw UserError("alp_gmm: potential_ks is empty");
    for (int k : p_.potential_ks)
      if (k < 1 || k > p_.fit_rate)
        throw UserError("alp_gmm: potential k " + std::to_string(k) + "; expected 1..fit_rate");
    if (!(p_.random_task_ratio >= 0 && p_.random_task_ratio <= 1))
      throw UserError("alp_gmm: random_task_ratio must lie in [0, 1]");
    if (p_.criterion != "aic" && p_.criterion != "bic")
      throw UserError("alp_gmm: criterion '" + p_.criterion + "'; expected aic or bic");
    if (p_.initial_dist) check_dist(*p_.initial_dist, "alp_gmm: initial_dist");
  }

  bool is_non_exploratory_task_sampling_available() const override { return fitted_; }

  Task sample_task() override {
    // Bootstrap under high expert knowledge: the env's easy region (origin -2).
    if (!fitted_ && p_.initial_dist) {
      last_origin_ = -2;
      return gaussian_task(*p_.initial_dist);
    }
    // Bootstrap, before the first fit, and a random_task_ratio share: uniform (origin -1).
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
    // ALP against the nearest earlier task (raw coordinates), once more than 5 are known.
    double alp = 0;
    if (history_.size() > 5) {
      double best = std::numeric_limits<double>::infinity();
      double nearest_ret = 0;
      for (const auto& [t, r] : history_) {
        double dist = 0;
        for (int i = 0; i < dims(); ++i) dist += (t[i] - task[i]) * (t[i] - task[i]);
        if (dist < best) {
          best = dist;
          nearest_ret = r;
        }
      }
      alp = std::abs(ret - nearest_ret);
    }
    history_.push_back({task, ret});
    origins_.push_back(last_origin_);
    alps_.push_back(alp);
    // Refit on the last fit_rate [task, ALP] vectors every fit_rate episodes.
    if (history_.size() % static_cast<std::size_t>(p_.fit_rate) == 0) {
      Eigen::MatrixXd x(p_.fit_rate, dims() + 1);
      const std::size_t start = history_.size() - p_.fit_rate;
      for (int row = 0; row < p_.fit_rate; ++row) {
        for (int i = 0; i < dims(); ++i) x(row, i) = history_[start + row].first[i];
        x(row, dims()) = alps_[start + row];
      }
      gmm_ = fit_best_gmm(x, p_.potential_ks, p_.criterion, fit_rng_);
      fitted_ = true;
      ++fits_;
    }
  }

  nlohmann::json dump() const override {
    nlohmann::json j = Teacher::dump();
    j["episodes"] = history_.size();
    j["fits"] = fits_;
    j["task_origins"] = origins_;  // -2 initial dist, -1 random, j component index
    if (fitted_) {
      nlohmann::json comps = nlohmann::json::array();
      for (int c = 0; c < gmm_.k(); ++c)
        comps.push_back(
            {{"weight", gmm_.weights[c]},
             {"mean", std::vector<double>(gmm_.means[c].data(),
                                          gmm_.means[c].data() + gmm_.means[c].size())}});
      j["components"] = std::move(comps);
    }
    return j;
  }
  const char* name() const override { return "alp_gmm"; }

 private:
  // Component index with probability proportional to its mean ALP (uniform when all are 0).
  int pick_component() {
    double total = 0;
    for (int c = 0; c < gmm_.k(); ++c) total += std::max(0.0, gmm_.means[c][dims()]);
    if (total <= 0) return std::min(gmm_.k() - 1, static_cast<int>(rng_.uniform() * gmm_.k()));
    double u = rng_.uniform() * total;
    for (int c = 0; c < gmm_.k(); ++c) {
      u -= std::max(0.0, gmm_.means[c][dims()]);
      if (u < 0) return c;
    }
    return gmm_.k() - 1;
  }
  // A draw from component c with the ALP coordinate dropped, clipped to the box.
  Task from_component(int c) {
    last_origin_ = c;
    const Eigen::VectorXd s = sample_component(gmm_, c, rng_);
    Task task(dims());
    for (int i = 0; i < dims(); ++i) task[i] = static_cast<float>(s[i]);
    clip(task);
    return task;
  }

  AlpGmmParams p_;
  Rng fit_rng_;
  std::vector<std::pair<Task, double>> history_;
  std::vector<double> alps_;
  std::vector<int> origins_;
  int last_origin_ = -1;
  Gmm gmm_;
  bool fitted_ = false;
  int fits_ = 0;
};

}  // namespace

std::unique_ptr<Teacher> make_alp_gmm_teacher(std::vector<float> mins, std::vector<float> maxs,
                                              std::uint64_t seed, AlpGmmParams params) {
  return std::make_unique<AlpGmmTeacher>(std::move(mins), std::move(maxs), seed, std::move(params));
}

}  // namespace cradle::teach

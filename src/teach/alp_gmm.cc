// ALP-GMM: each episode's ALP is |return - return of the nearest earlier task|; every fit_rate
// episodes, GMMs on the last fit_rate [task, ALP] vectors are refitted, and a component is drawn
// with probability proportional to its mean ALP.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "core/error.h"
#include "teach/gmm_teacher.h"

namespace cradle::teach {
namespace {

class AlpGmmTeacher final : public GmmTeacher {
 public:
  AlpGmmTeacher(std::vector<float> mins, std::vector<float> maxs, std::uint64_t seed,
                AlpGmmParams p)
      : GmmTeacher(std::move(mins), std::move(maxs), seed, "alp_gmm",
                   {p.fit_rate, p.potential_ks, p.random_task_ratio, p.initial_dist}),
        criterion_(std::move(p.criterion)) {
    if (criterion_ != "aic" && criterion_ != "bic")
      throw UserError("alp_gmm: criterion '" + criterion_ + "'; expected aic or bic");
  }

  void episodic_update(const Task& task, double ret, bool) override {
    check_episode(task, ret);
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
    alps_.push_back(alp);
    // Refit on the last fit_rate [task, ALP] vectors every fit_rate episodes.
    if (record_episode()) {
      Eigen::MatrixXd x(fit_rate(), dims() + 1);
      const std::size_t start = history_.size() - fit_rate();
      for (int row = 0; row < fit_rate(); ++row) {
        for (int i = 0; i < dims(); ++i) x(row, i) = history_[start + row].first[i];
        x(row, dims()) = alps_[start + row];
      }
      refit(x, criterion_);
    }
  }

  nlohmann::json dump() const override {
    nlohmann::json j = GmmTeacher::dump();
    if (is_non_exploratory_task_sampling_available()) {
      nlohmann::json comps = nlohmann::json::array();
      for (int c = 0; c < gmm().k(); ++c)
        comps.push_back(
            {{"weight", gmm().weights[c]},
             {"mean", std::vector<double>(gmm().means[c].data(),
                                          gmm().means[c].data() + gmm().means[c].size())}});
      j["components"] = std::move(comps);
    }
    return j;
  }
  const char* name() const override { return "alp_gmm"; }

 private:
  // A component's mean ALP, its negative part cut.
  double progress(int c) const override { return std::max(0.0, gmm().means[c][dims()]); }

  std::string criterion_;
  std::vector<std::pair<Task, double>> history_;
  std::vector<double> alps_;
};

}  // namespace

std::unique_ptr<Teacher> make_alp_gmm_teacher(std::vector<float> mins, std::vector<float> maxs,
                                              std::uint64_t seed, AlpGmmParams params) {
  return std::make_unique<AlpGmmTeacher>(std::move(mins), std::move(maxs), seed, std::move(params));
}

}  // namespace cradle::teach

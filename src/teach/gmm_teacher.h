// What ALP-GMM and Covar-GMM share: the checks of their common parameters and the sampling
// policy (expert-knowledge bootstrap, then uniform until the first fit and for a random_task_ratio
// share, else a GMM component drawn in proportion to its learning progress).
#pragma once

#include <Eigen/Dense>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/rng.h"
#include "teach/gmm.h"
#include "teach/teacher.h"

namespace cradle::teach {

// The parameters both GMM teachers have (see AlpGmmParams, CovarGmmParams).
struct GmmTeacherParams {
  int fit_rate = 250;
  std::vector<int> potential_ks;
  double random_task_ratio = 0.2;
  std::optional<DiagGaussian> initial_dist;
};

class GmmTeacher : public Teacher {
 public:
  bool is_non_exploratory_task_sampling_available() const override { return fitted_; }
  Task sample_task() override;
  Task non_exploratory_task_sampling() override;
  // Teacher's records plus episodes, fits and the origin of every task (-2 initial dist, -1
  // random, j component index).
  nlohmann::json dump() const override;

 protected:
  // Throws UserError prefixed with `who` ("alp_gmm") on a bad shared parameter.
  GmmTeacher(std::vector<float> mins, std::vector<float> maxs, std::uint64_t seed,
             const std::string& who, GmmTeacherParams params);
  // Learning progress of component c of gmm() (>= 0).
  virtual double progress(int c) const = 0;
  // Books the episode just played; true when fit_rate episodes have passed since the last fit.
  bool record_episode();
  // Fits the best of potential_ks components to the rows of x by `criterion` (aic or bic); false
  // (the previous mixture kept, failed_fits counted) when no fit is usable.
  bool refit(const Eigen::MatrixXd& x, const std::string& criterion);

  int fit_rate() const { return p_.fit_rate; }
  const Gmm& gmm() const { return gmm_; }

 private:
  // Component index in proportion to its progress (uniform when all are 0).
  int pick_component();
  // A draw from component c, the coordinates past the task dropped, clipped to the box.
  Task from_component(int c);

  GmmTeacherParams p_;
  Rng fit_rng_;
  Gmm gmm_;
  bool fitted_ = false;
  int fits_ = 0, failed_fits_ = 0;
  std::vector<int> origins_;
  int last_origin_ = -1;
};

}  // namespace cradle::teach

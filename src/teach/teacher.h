// Curriculum teachers (TeachMyAgent ACL methods): each proposes flat float task vectors inside a
// box and learns from the return and success of the episode played on them. Env-agnostic by design.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/rng.h"

namespace cradle::teach {

using Task = std::vector<float>;

// A diagonal Gaussian in the teacher's task space (an env's easy region, SPDL's target).
struct DiagGaussian {
  std::vector<float> mean, variance;
};

// The student's value function V(s) on a batch of states (SAC's V network, PPO's value head).
using ValueEstimator =
    std::function<std::vector<float>(const std::vector<std::vector<float>>& states)>;

// The interface every teacher implements (hooks named as in TeachMyAgent's AbstractTeacher).
class Teacher {
 public:
  // Throws UserError when the bounds are empty, of different sizes, non-finite or min > max.
  Teacher(std::vector<float> mins, std::vector<float> maxs, std::uint64_t seed);
  virtual ~Teacher() = default;

  // A task for the next training episode.
  virtual Task sample_task() = 0;
  // A task with no exploration noise (curriculum snapshots); by default a normal sample.
  virtual Task non_exploratory_task_sampling() { return sample_task(); }
  virtual bool is_non_exploratory_task_sampling_available() const { return true; }
  // Only step-driven teachers (SPDL) use these two.
  virtual void record_initial_state(const Task& /*task*/, const std::vector<float>& /*s0*/) {}
  virtual void step_update(const std::vector<float>& /*s*/, const std::vector<float>& /*a*/,
                           double /*r*/, const std::vector<float>& /*s_next*/, bool /*done*/) {}
  // The student hands its value function over once; only SPDL uses it.
  virtual void set_value_estimator(ValueEstimator /*estimator*/) {}
  // End of a training episode played on `task`.
  virtual void episodic_update(const Task& task, double ret, bool success) = 0;
  // Book-keeping as JSON (name, bounds, and the teacher's own records).
  virtual nlohmann::json dump() const;
  virtual const char* name() const = 0;

  int dims() const { return static_cast<int>(mins_.size()); }
  const std::vector<float>& mins() const { return mins_; }
  const std::vector<float>& maxs() const { return maxs_; }

 protected:
  // Uniform in the whole box.
  Task uniform_task();
  // Clips every coordinate into the box.
  void clip(Task& task) const;
  // A draw from a diagonal Gaussian, clipped to the box.
  Task gaussian_task(const DiagGaussian& dist);
  // Throws UserError (naming `what`) unless dist has dims() finite means and variances >= 0.
  void check_dist(const DiagGaussian& dist, const std::string& what) const;

  std::vector<float> mins_, maxs_;
  Rng rng_;
};

// Uniform sampling in the box, no state.
std::unique_ptr<Teacher> make_random_teacher(std::vector<float> mins, std::vector<float> maxs,
                                             std::uint64_t seed);

// ADR (automatic domain randomisation): a box grown outward from one point where returns are high.
struct AdrParams {
  float step_size = 0.1f;            // bound move, in task units
  double boundary_prob = 0.5;        // class default (the benchmark passes 0.7)
  int queue_len = 10;                // returns per bound and dimension before a decision
  double max_reward_thr = 180.0;     // expand when the queue mean is at least this
  double min_reward_thr = 0.0;       // shrink when the queue mean is at most this
  std::vector<float> initial_point;  // empty: a uniformly random point (low expert knowledge)
};
// Throws UserError on a bad parameter (non-positive step or queue, probability outside [0, 1],
// thresholds in the wrong order, an initial point of the wrong size or outside the box).
std::unique_ptr<Teacher> make_adr_teacher(std::vector<float> mins, std::vector<float> maxs,
                                          std::uint64_t seed, AdrParams params = {});

// RIAC: a tree of regions split where absolute learning progress differs; samples regions by ALP.
struct RiacParams {
  int max_region_size = 200;   // maxlen: a leaf holding more pairs is split (benchmark 150)
  int alp_window = 0;          // 0: = max_region_size
  int nb_split_attempts = 50;  // benchmark 75
  double min_region_size = 0;  // minlen; 0: max_region_size / 20
  double min_dims_range_ratio = 1.0 / 6.0;  // benchmark 0.1
  double discard_ratio = 0.25;              // oldest share dropped when no split is valid
};
// Throws UserError on a bad parameter.
std::unique_ptr<Teacher> make_riac_teacher(std::vector<float> mins, std::vector<float> maxs,
                                           std::uint64_t seed, RiacParams params = {});

// ALP-GMM: GMMs fitted on [task, absolute learning progress]; components sampled by mean ALP.
struct AlpGmmParams {
  int fit_rate = 250;  // benchmark 150; also the bootstrap length
  std::vector<int> potential_ks = {2, 3, 4, 5, 6, 7, 8, 9, 10};  // benchmark 2..9
  double random_task_ratio = 0.2;                                // benchmark 0.05
  std::string criterion = "aic";                                 // or "bic"
  std::optional<DiagGaussian> initial_dist;  // high expert knowledge: bootstrap tasks from it
};
// Throws UserError on a bad parameter.
std::unique_ptr<Teacher> make_alp_gmm_teacher(std::vector<float> mins, std::vector<float> maxs,
                                              std::uint64_t seed, AlpGmmParams params = {});

}  // namespace cradle::teach

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

// The largest return (and task coordinate) in magnitude a teacher accepts. No env comes near it
// (TeachMyAgent's returns are in the hundreds), and it keeps the GMM teachers' squared deviations
// (at most ~1e31 per value) far from overflow.
inline constexpr double kMaxAbsReturn = 1e15;

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
  // Only step-driven teachers (SPDL) use these two; every teacher checks their values (a
  // UserError on a task of another size, non-finite values or a reward beyond kMaxAbsReturn).
  virtual void record_initial_state(const Task& task, const std::vector<float>& s0);
  virtual void step_update(const std::vector<float>& s, const std::vector<float>& a, double r,
                           const std::vector<float>& s_next, bool done);
  // The student hands its value function over once; only SPDL uses it.
  virtual void set_value_estimator(ValueEstimator /*estimator*/) {}
  // End of a training episode played on `task`. Throws UserError (before changing anything) when
  // the task has another size than dims() or a coordinate that is not finite or beyond
  // kMaxAbsReturn, or when the return is.
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
  // subspace: mean uniform in the box, std 10 % of each range; else the box centre, std range / 4.
  DiagGaussian dist_from_bounds(bool subspace);
  // The checks of episodic_update, record_initial_state and step_update, for their overrides.
  void check_episode(const Task& task, double ret) const;
  void check_initial_state(const Task& task, const std::vector<float>& s0) const;
  void check_step(const std::vector<float>& s, const std::vector<float>& a, double r,
                  const std::vector<float>& s_next) const;
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

// Covar-GMM: GMMs fitted on [task, relative time, return]; components sampled by their positive
// time-return covariance (learning progress).
struct CovarGmmParams {
  int fit_rate = 250;                                            // benchmark 150
  std::vector<int> potential_ks = {2, 3, 4, 5, 6, 7, 8, 9, 10};  // benchmark 2..14
  double random_task_ratio = 0.2;                                // benchmark 0.1
  bool absolute_lp = false;                  // |covariance| instead of its positive part
  std::optional<DiagGaussian> initial_dist;  // high expert knowledge: bootstrap tasks from it
};
// Throws UserError on a bad parameter.
std::unique_ptr<Teacher> make_covar_gmm_teacher(std::vector<float> mins, std::vector<float> maxs,
                                                std::uint64_t seed, CovarGmmParams params = {});

// Self-Paced Deep RL (SPDL): a Gaussian over tasks moved toward the target distribution as the
// student's value of its tasks rises; step-driven (record_initial_state, step_update) and needs
// set_value_estimator. Class defaults; the benchmark passes update_frequency 50000, alpha_offset
// 10, zeta 0.25, use_avg_performance true.
struct SelfPacedParams {
  long update_frequency = 100000;    // env steps between updates (CLI default)
  long update_offset = 200000;       // no update before this many steps
  int alpha_offset = 0;              // iterations with alpha = 0
  double zeta = 0.05;                // alpha's share of the performance
  double max_kl = 0.1;               // trust region KL(old || new) (CLI default 0.8)
  bool use_avg_performance = false;  // performance = mean discounted return, else mean value
  double discount_factor = 0.99;     // the student's gamma
  std::optional<DiagGaussian> initial_dist;  // none: a random sub-region (mean uniform, std 10 %)
  std::optional<DiagGaussian> target_dist;   // none: centre of the box, std range / 4
};
// Throws UserError on a bad parameter or distribution.
std::unique_ptr<Teacher> make_self_paced_teacher(std::vector<float> mins, std::vector<float> maxs,
                                                 std::uint64_t seed, SelfPacedParams params = {});

// GoalGAN: an LSGAN that learns to generate goals of intermediate difficulty (LibTorch). Class
// defaults; the benchmark passes state_noise_level 0.1, p_old 0.1, use_pretrained_samples true.
struct GoalGanParams {
  double state_noise_level = 0.01;           // goal noise, share of each range
  double success_distance_threshold = 0.01;  // share of the box diagonal
  int update_size = 100;                     // labelled goals per GAN training
  int n_rollouts = 2;                        // episodes per generated goal
  double goid_lb = 0.25, goid_ub = 0.75;     // "goal of intermediate difficulty" success rates
  double p_old = 0.2;                        // share of replayed successful goals
  bool use_pretrained_samples = false;       // pretrain on initial_dist (or a random sub-region)
  std::optional<DiagGaussian> initial_dist;
  int pretrain_samples = 1000, pretrain_iterations = 500;  // the reference's fixed values
  int train_iterations = 250, batch_size = 64;
  double lr = 1e-3;  // RMSProp, both networks
};
// Throws UserError on a bad parameter.
std::unique_ptr<Teacher> make_goal_gan_teacher(std::vector<float> mins, std::vector<float> maxs,
                                               std::uint64_t seed, GoalGanParams params = {});

// Setter-Solver: a conditional RealNVP setter proposes goals of a desired feasibility, a judge
// learns feasibility from binary success (LibTorch). Class defaults; the benchmark passes
// update_frequency 50, setter_loss_noise_ub 0.1, setter_hidden_size 64.
struct SetterSolverParams {
  int update_frequency = 100;          // episodes between training steps
  double setter_loss_noise_ub = 0.01;  // validity jitter U(0, ub) (CLI default 0.05)
  int setter_hidden_size = 128;        // width of the coupling nets
  double lr = 3e-4;                    // Adam, setter and judge
};
// Throws UserError on a bad parameter.
std::unique_ptr<Teacher> make_setter_solver_teacher(std::vector<float> mins,
                                                    std::vector<float> maxs, std::uint64_t seed,
                                                    SetterSolverParams params = {});

}  // namespace cradle::teach

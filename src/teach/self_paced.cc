// Self-Paced Deep RL (SPDL): a full-covariance Gaussian over tasks, moved every update_frequency
// env steps to maximise the student's value of its tasks while approaching the target
// distribution (penalty alpha * KL), each move bounded by KL(old || new) <= max_kl (a trust
// region, solved TRPO-style: natural gradient, scaled step, backtracking line search).
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <deque>
#include <string>
#include <utility>

#include "core/error.h"
#include "teach/gmm.h"
#include "teach/teacher.h"

namespace cradle::teach {
namespace {

// A Gaussian from its parameter vector [mean, log diag of L, strict lower of L row-major].
struct Gauss {
  Eigen::VectorXd mean;
  Eigen::MatrixXd l;  // Cholesky factor of the covariance
};

Gauss unpack(const Eigen::VectorXd& theta, int d) {
  Gauss g{theta.head(d), Eigen::MatrixXd::Zero(d, d)};
  for (int i = 0; i < d; ++i) g.l(i, i) = std::exp(theta[d + i]);
  int k = 2 * d;
  for (int i = 0; i < d; ++i)
    for (int j = 0; j < i; ++j) g.l(i, j) = theta[k++];
  return g;
}

Eigen::VectorXd pack(const Eigen::VectorXd& mean, const Eigen::MatrixXd& l) {
  const int d = static_cast<int>(mean.size());
  Eigen::VectorXd theta(2 * d + d * (d - 1) / 2);
  theta.head(d) = mean;
  for (int i = 0; i < d; ++i) theta[d + i] = std::log(l(i, i));
  int k = 2 * d;
  for (int i = 0; i < d; ++i)
    for (int j = 0; j < i; ++j) theta[k++] = l(i, j);
  return theta;
}

// log N(c | g) for every column of c (without the constant, which cancels in every use).
Eigen::VectorXd log_density(const Gauss& g, const Eigen::MatrixXd& c) {
  const Eigen::MatrixXd z = g.l.triangularView<Eigen::Lower>().solve(c.colwise() - g.mean);
  const double log_det = 2.0 * g.l.diagonal().array().log().sum();
  return (-0.5 * (z.colwise().squaredNorm().array() + log_det)).matrix().transpose();
}

// KL(p || q) between two Gaussians.
double kl(const Gauss& p, const Gauss& q) {
  const int d = static_cast<int>(p.mean.size());
  const auto lq = q.l.triangularView<Eigen::Lower>();
  const Eigen::MatrixXd a = lq.solve(p.l);  // Lq^-1 Lp: tr(Sq^-1 Sp) = |a|^2
  const Eigen::VectorXd b = lq.solve(q.mean - p.mean);
  const double log_det_ratio =
      2.0 * (q.l.diagonal().array().log().sum() - p.l.diagonal().array().log().sum());
  return 0.5 * (a.squaredNorm() + b.squaredNorm() - d + log_det_ratio);
}

class SelfPacedTeacher final : public Teacher {
 public:
  SelfPacedTeacher(std::vector<float> mins, std::vector<float> maxs, std::uint64_t seed,
                   SelfPacedParams p)
      : Teacher(std::move(mins), std::move(maxs), seed), p_(std::move(p)) {
    // Check the parameters before anything depends on them.
    if (p_.update_frequency < 1) throw UserError("self_paced: update_frequency must be >= 1");
    if (p_.update_offset < 0) throw UserError("self_paced: update_offset must be >= 0");
    if (p_.alpha_offset < 0) throw UserError("self_paced: alpha_offset must be >= 0");
    if (!(p_.zeta >= 0)) throw UserError("self_paced: zeta must be >= 0");
    if (!(p_.max_kl > 0)) throw UserError("self_paced: max_kl must be > 0");
    if (!(p_.discount_factor > 0 && p_.discount_factor <= 1))
      throw UserError("self_paced: discount_factor must lie in (0, 1]");
    // Start at the initial distribution (else a random sub-region); aim at the target (else the
    // whole box).
    const DiagGaussian init = p_.initial_dist ? *p_.initial_dist : dist_from_bounds(true);
    const DiagGaussian target = p_.target_dist ? *p_.target_dist : dist_from_bounds(false);
    check_dist(init, "self_paced: initial_dist");
    check_dist(target, "self_paced: target_dist");
    current_ = to_gauss(init);
    target_ = to_gauss(target);
    record(0.0);
  }

  Task sample_task() override {
    Eigen::VectorXd n(dims());
    for (int i = 0; i < dims(); ++i) n[i] = standard_normal(rng_);
    const Eigen::VectorXd c = current_.mean + current_.l * n;
    Task task(dims());
    for (int i = 0; i < dims(); ++i) task[i] = static_cast<float>(c[i]);
    clip(task);
    return task;
  }

  void set_value_estimator(ValueEstimator estimator) override { value_ = std::move(estimator); }

  void record_initial_state(const Task& task, const std::vector<float>& s0) override {
    check_initial_state(task, s0);
    // At most 1000 (state, task) pairs; the oldest go first.
    if (contexts_.size() == 1000) contexts_.pop_front();
    contexts_.push_back({s0, task});
  }

  void step_update(const std::vector<float>& s, const std::vector<float>& a, double r,
                   const std::vector<float>& s_next, bool done) override {
    check_step(s, a, r, s_next);
    // The discounted return of the running episode.
    ++steps_;
    episode_return_ += discount_ * r;
    discount_ *= p_.discount_factor;
    if (done) {
      returns_.push_back(episode_return_);
      episode_return_ = 0;
      discount_ = 1;
    }
    if (steps_ >= p_.update_offset && steps_ % p_.update_frequency == 0 && !contexts_.empty() &&
        !returns_.empty())
      update();
  }

  void episodic_update(const Task& task, double ret, bool) override { check_episode(task, ret); }

  nlohmann::json dump() const override {
    nlohmann::json j = Teacher::dump();
    j["steps"] = steps_;
    j["iterations"] = iteration_;
    j["history"] = history_;  // per update: steps, iteration, mean, covariance, kl, alpha
    return j;
  }
  const char* name() const override { return "self_paced"; }

 private:
  // Diagonal Gaussian -> Cholesky form; a variance of 0 becomes 1e-6.
  Gauss to_gauss(const DiagGaussian& g) const {
    Gauss out{Eigen::VectorXd(dims()), Eigen::MatrixXd::Zero(dims(), dims())};
    for (int i = 0; i < dims(); ++i) {
      out.mean[i] = g.mean[i];
      out.l(i, i) = std::sqrt(g.variance[i] == 0.f ? 1e-6 : static_cast<double>(g.variance[i]));
    }
    return out;
  }

  // One trust-region step on the buffered (s0, task) pairs.
  void update() {
    if (!value_)
      throw UserError(
          "self_paced: no value estimator; the student must call set_value_estimator before the "
          "first update");
    // Values of the buffered initial states; tasks as columns.
    std::vector<std::vector<float>> states;
    Eigen::MatrixXd c(dims(), static_cast<int>(contexts_.size()));
    for (std::size_t i = 0; i < contexts_.size(); ++i) {
      states.push_back(contexts_[i].first);
      for (int k = 0; k < dims(); ++k) c(k, static_cast<int>(i)) = contexts_[i].second[k];
    }
    // The buffer and the iteration count change only once the estimator's values are checked,
    // so an estimator that throws or misbehaves leaves the teacher as it was.
    const std::vector<float> values = value_(states);
    if (values.size() != states.size())
      throw UserError("self_paced: the value estimator returned " + std::to_string(values.size()) +
                      " values for " + std::to_string(states.size()) +
                      " states; expected one each");
    // A NaN value would turn the objective into NaN and silently freeze the curriculum.
    for (std::size_t i = 0; i < values.size(); ++i)
      if (!std::isfinite(values[i]))
        throw UserError("self_paced: the value estimator's value " + std::to_string(i) + " is " +
                        (std::isnan(values[i]) ? std::string("nan") : std::to_string(values[i])) +
                        "; expected finite values");
    contexts_.clear();
    ++iteration_;
    const Eigen::VectorXd v =
        Eigen::Map<const Eigen::VectorXf>(values.data(), values.size()).cast<double>();
    // Alpha: zero for the first alpha_offset iterations, then a zeta share of the performance
    // per unit of KL to the target.
    double performance = v.mean();
    if (p_.use_avg_performance) {
      performance = 0;
      for (double r : returns_) performance += r;
      performance /= static_cast<double>(returns_.size());
    }
    returns_.clear();
    const double kl_target = kl(current_, target_);
    const double alpha =
        iteration_ < p_.alpha_offset
            ? 0.0
            : std::min(p_.zeta * std::max(performance, 0.0) / std::max(kl_target, 1e-10), 1e5);
    // Objective: importance-weighted value minus alpha * KL(new || target).
    const int d = dims();
    const Gauss old = current_;
    const Eigen::VectorXd theta0 = pack(old.mean, old.l);
    const Eigen::VectorXd log_old = log_density(old, c);
    auto objective = [&](const Eigen::VectorXd& theta) {
      const Gauss g = unpack(theta, d);
      const Eigen::VectorXd ratio = (log_density(g, c) - log_old).array().exp().matrix();
      return ratio.dot(v) / static_cast<double>(v.size()) - alpha * kl(g, target_);
    };
    auto kl_old = [&](const Eigen::VectorXd& theta) { return kl(old, unpack(theta, d)); };
    // Gradient and Fisher matrix (Hessian of KL(old || .) at old) by central differences: the
    // parameter vector is small (d + d(d+1)/2).
    const int n = static_cast<int>(theta0.size());
    Eigen::VectorXd grad(n);
    Eigen::MatrixXd fisher(n, n);
    const double h = 1e-5, hh = 1e-4;
    for (int i = 0; i < n; ++i) {
      Eigen::VectorXd e = Eigen::VectorXd::Zero(n);
      e[i] = h;
      grad[i] = (objective(theta0 + e) - objective(theta0 - e)) / (2 * h);
    }
    for (int i = 0; i < n; ++i)
      for (int j = 0; j <= i; ++j) {
        Eigen::VectorXd ei = Eigen::VectorXd::Zero(n), ej = Eigen::VectorXd::Zero(n);
        ei[i] = hh;
        ej[j] = hh;
        fisher(i, j) = fisher(j, i) = (kl_old(theta0 + ei + ej) - kl_old(theta0 + ei - ej) -
                                       kl_old(theta0 - ei + ej) + kl_old(theta0 - ei - ej)) /
                                      (4 * hh * hh);
      }
    // Natural-gradient direction (damping 0.01, as the reference's conjugate gradient), scaled
    // so the quadratic KL model reaches max_kl.
    const Eigen::MatrixXd damped = fisher + 0.01 * Eigen::MatrixXd::Identity(n, n);
    const Eigen::VectorXd s = damped.ldlt().solve(grad);
    const double shs = s.dot(damped * s);
    bool accepted = false;
    if (shs > 0 && std::isfinite(shs)) {
      const Eigen::VectorXd full = std::sqrt(2 * p_.max_kl / shs) * s;
      const double before = objective(theta0);
      // Backtracking: halve up to 10 times until KL(old || new) <= 1.5 max_kl and the objective
      // improves (the documented intent; the reference's "or" would accept a worse step).
      for (int k = 0; k < 10 && !accepted; ++k) {
        const Eigen::VectorXd theta = theta0 + std::pow(0.5, k) * full;
        const double after = objective(theta);
        if (std::isfinite(after) && kl_old(theta) <= 1.5 * p_.max_kl && after > before) {
          current_ = unpack(theta, d);
          accepted = true;
        }
      }
    }
    record(alpha);
  }

  // Book-keeping of the current distribution.
  void record(double alpha) {
    const Eigen::MatrixXd cov = current_.l * current_.l.transpose();
    history_.push_back(
        {{"steps", steps_},
         {"iteration", iteration_},
         {"mean", std::vector<double>(current_.mean.data(), current_.mean.data() + dims())},
         {"covariance", std::vector<double>(cov.data(), cov.data() + cov.size())},
         {"kl", kl(current_, target_)},
         {"alpha", alpha}});
  }

  SelfPacedParams p_;
  Gauss current_, target_;
  ValueEstimator value_;
  std::deque<std::pair<std::vector<float>, Task>> contexts_;
  std::vector<double> returns_;
  double episode_return_ = 0, discount_ = 1;
  long steps_ = 0;
  int iteration_ = 0;
  nlohmann::json history_ = nlohmann::json::array();
};

}  // namespace

std::unique_ptr<Teacher> make_self_paced_teacher(std::vector<float> mins, std::vector<float> maxs,
                                                 std::uint64_t seed, SelfPacedParams params) {
  return std::make_unique<SelfPacedTeacher>(std::move(mins), std::move(maxs), seed,
                                            std::move(params));
}

}  // namespace cradle::teach

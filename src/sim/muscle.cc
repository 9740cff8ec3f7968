// Muscle actuation (mimo_core.md §3.2): two antagonistic virtual muscles per actuated joint, with
// first-order activation dynamics and MuJoCo-style force-length-velocity curves. The model
// computes the joint torque itself and sends it through the composed scene's unclamped motors as
// ctrl = torque / gear, so the shared mjModel is never written.
//
// Activation updates per env step: one per physics substep (substep()), none in apply(). With
// frame_skip N that is N updates, each just before an mj_step, which matches the BabyBench fork
// (one update in action() plus N − 1 in the later substeps); upstream MIMo makes N + 1 (one in
// action() and one before every substep).
#include "sim/muscle.h"

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "sim/actuation.h"

namespace cradle::sim {

namespace muscle {

double bump(double length, double lo, double mid, double hi) {
  if (length <= lo || length >= hi) return 0;
  const double left = 0.5 * (lo + mid);   // inflection point on the rising side
  const double right = 0.5 * (mid + hi);  // inflection point on the falling side
  auto sq = [](double x) { return x * x; };
  if (length < left) return 0.5 * sq(length - lo) / sq(left - lo);
  if (length < mid) return 1 - 0.5 * sq(length - mid) / sq(mid - left);
  if (length < right) return 1 - 0.5 * sq(length - mid) / sq(right - mid);
  return 0.5 * sq(length - hi) / sq(hi - right);
}

double force_length(double length) {
  const double shoulder_mid = 0.5 * (kLengthMin + 0.95);
  return bump(length, kLengthMin, 1, kLengthMax) +
         0.15 * bump(length, kLengthMin, shoulder_mid, 0.95);
}

double force_velocity(double velocity) {
  const double c = kVelocityForceMax - 1;  // velocity at which the lengthening gain saturates
  if (velocity <= -1) return 0;
  if (velocity <= 0) return (velocity + 1) * (velocity + 1);
  if (velocity <= c) return kVelocityForceMax - (c - velocity) * (c - velocity) / c;
  return kVelocityForceMax;
}

double force_passive(double length) {
  const double b = 0.5 * (kLengthMax + 1);  // where the cubic turns linear
  if (length <= 1) return 0;
  const double x = (length - 1) / (b - 1);
  if (length <= b) return 0.25 * kPassiveForceMax * x * x * x;
  return 0.25 * kPassiveForceMax * (1 + 3 * (length - b) / (b - 1));
}

double force(double length, double velocity, double activation) {
  return force_length(length) * force_velocity(velocity) * activation + force_passive(length);
}

}  // namespace muscle

namespace {

constexpr ActuationModel kKind = ActuationModel::kMuscle;

// Fallbacks when the actuators carry no user triple (VMAX, FMAX_neg, FMAX_pos).
constexpr double kDefaultVmax = 1;
constexpr double kDefaultFmax = 5;

class Muscle final : public Actuation {
 public:
  explicit Muscle(const mjModel* m) : m_(m) {
    const std::vector<int> ids = mimo_actuators(m);
    const int n = static_cast<int>(ids.size());
    for (int id : ids) units_.push_back(make_unit(m, id));
    // Action: negative-direction muscles first, then positive-direction ones.
    space_ = Box::uniform({2 * n}, DType::kFloat32, 0, 1);
    double fmax_sum = 0;
    for (const Unit& u : units_) fmax_sum += u.fmax_neg + u.fmax_pos;
    cost_scale_ = n > 0 && fmax_sum != 0 ? 1.0 / (2 * n * fmax_sum) : 0.0;
    activation_.assign(2 * n, 0.0);
    target_.assign(2 * n, 0.0);
    force_.assign(2 * n, 0.0);
  }

  const Box& action_space() const override { return space_; }

  void apply(std::span<const double> action, mjData* d) override {
    if (action.size() != target_.size()) {
      throw std::invalid_argument("muscle action has the wrong size");
    }
    // New targets; activations only move in substep().
    for (size_t j = 0; j < target_.size(); ++j) target_[j] = std::clamp(action[j], 0.0, 1.0);
    update(d);
  }

  void substep(mjData* d) override {
    // One Euler step of da/dt = (target − a) / τ_act over the physics timestep.
    const double rate = m_->opt.timestep / muscle::kActivationTime;
    for (size_t j = 0; j < activation_.size(); ++j) {
      activation_[j] = std::clamp(activation_[j] + rate * (target_[j] - activation_[j]), 0.0, 1.0);
    }
    update(d);
  }

  int observation_size() const override { return 4 * static_cast<int>(units_.size()); }

  void observe(const mjData* d, std::span<double> out) const override {
    (void)d;
    // [activations (2n), F1·FMAX_neg (n), F2·FMAX_pos (n)].
    const size_t n = units_.size();
    std::copy(activation_.begin(), activation_.end(), out.begin());
    for (size_t i = 0; i < n; ++i) {
      out[2 * n + i] = force_[i] * units_[i].fmax_neg;
      out[3 * n + i] = force_[n + i] * units_[i].fmax_pos;
    }
  }

  double cost() const override {
    // Σ a² FMAX / (2n Σ FMAX) over both muscles of every joint.
    const size_t n = units_.size();
    double sum = 0;
    for (size_t i = 0; i < n; ++i) {
      sum += activation_[i] * activation_[i] * units_[i].fmax_neg;
      sum += activation_[n + i] * activation_[n + i] * units_[i].fmax_pos;
    }
    return sum * cost_scale_;
  }

  void reset(mjData* d) override {
    std::fill(activation_.begin(), activation_.end(), 0.0);
    std::fill(target_.begin(), target_.end(), 0.0);
    update(d);
  }

 private:
  // Constants of one actuated joint and its two muscles (1: pulls negative, 2: pulls positive).
  struct Unit {
    int actuator, qpos, dof;
    double gear, springref;
    double arm_neg, arm_pos;  // moment arms m1 > 0, m2 < 0
    double ref_neg, ref_pos;  // fibre lengths at springref
    double vmax, fmax_neg, fmax_pos;
  };

  static Unit make_unit(const mjModel* m, int id) {
    const int joint = actuated_joint(m, id);
    // Unclamped motors on springless joints: the model owns the whole torque.
    require_actuator(
        m->actuator_dyntype[id] == mjDYN_NONE && m->actuator_gaintype[id] == mjGAIN_FIXED &&
            m->actuator_biastype[id] == mjBIAS_NONE && m->actuator_gainprm[id * mjNGAIN] == 1,
        m, id, kKind, "is not a motor");
    require_actuator(!m->actuator_ctrllimited[id] && !m->actuator_forcelimited[id], m, id, kKind,
                     "is control- or force-limited (scene composed for another actuation model?)");
    require_actuator(m->jnt_stiffness[joint] == 0, m, id, kKind,
                     "drives a joint with stiffness (scene composed for another actuation model?)");
    require_actuator(m->jnt_limited[joint], m, id, kKind, "drives a joint without a range");
    require_actuator(m->actuator_gear[6 * id] != 0, m, id, kKind, "has zero gear");

    Unit u{.actuator = id,
           .qpos = m->jnt_qposadr[joint],
           .dof = m->jnt_dofadr[joint],
           .gear = m->actuator_gear[6 * id],
           .springref = m->qpos_spring[m->jnt_qposadr[joint]],
           .vmax = kDefaultVmax,
           .fmax_neg = kDefaultFmax,
           .fmax_pos = kDefaultFmax};
    if (m->nuser_actuator >= 3) {
      const mjtNum* user = m->actuator_user + id * m->nuser_actuator;
      u.vmax = user[0];
      u.fmax_neg = user[1];
      u.fmax_pos = user[2];
    }
    require_actuator(u.vmax > 0, m, id, kKind, "has a non-positive VMAX");

    // Joint range relative to springref; fibres span [lce_min, lce_max] across it, muscle 1
    // lengthening and muscle 2 shortening as the joint angle grows.
    const double phi_min = m->jnt_range[2 * joint] - u.springref;
    const double phi_max = m->jnt_range[2 * joint + 1] - u.springref;
    const double span = muscle::kFiberMax - muscle::kFiberMin + muscle::kEps;
    u.arm_neg = span / (phi_max - phi_min + muscle::kEps);
    u.arm_pos = span / (phi_min - phi_max - muscle::kEps);
    u.ref_neg = muscle::kFiberMin - u.arm_neg * phi_min;
    u.ref_pos = muscle::kFiberMin - u.arm_pos * phi_max;
    return u;
  }

  // Muscle lengths, velocities and forces from the joint state, then the joint torque as ctrl.
  void update(mjData* d) {
    const size_t n = units_.size();
    for (size_t i = 0; i < n; ++i) {
      const Unit& u = units_[i];
      const double angle = d->qpos[u.qpos] - u.springref;
      const double speed = d->qvel[u.dof];
      force_[i] =
          muscle::force(u.arm_neg * angle + u.ref_neg, u.arm_neg * speed / u.vmax, activation_[i]);
      force_[n + i] = muscle::force(u.arm_pos * angle + u.ref_pos, u.arm_pos * speed / u.vmax,
                                    activation_[n + i]);
      const double torque =
          -(u.arm_neg * force_[i] * u.fmax_neg + u.arm_pos * force_[n + i] * u.fmax_pos);
      d->ctrl[u.actuator] = torque / u.gear;
    }
  }

  const mjModel* m_;
  std::vector<Unit> units_;         // act:* actuators in action order
  std::vector<double> activation_;  // 2n: muscle-1s then muscle-2s
  std::vector<double> target_;      // 2n: clipped action
  std::vector<double> force_;       // 2n: normalised forces F (without FMAX)
  double cost_scale_ = 0;
  Box space_;
};

}  // namespace

std::unique_ptr<Actuation> make_muscle(const mjModel* m) { return std::make_unique<Muscle>(m); }

}  // namespace cradle::sim

// Positional actuation (mimo_core.md §3.3): the action is a target angle per actuated joint, in
// radians within the joint range, sent to the composed scene's position servos. Targets go to the
// servo of their own actuator id (the reference writes lock-equality data in equality order,
// which does not match actuator order). Joints held by an active lock equality keep their servo
// at the lock angle, as the BabyBench fork leaves their ctrl alone.
#include <algorithm>
#include <optional>
#include <stdexcept>
#include <vector>

#include "sim/actuation.h"

namespace cradle::sim {
namespace {

constexpr ActuationModel kKind = ActuationModel::kPositional;

// The angle an active single-joint equality holds a joint at (qpos0 + polycoef a0), if any.
std::optional<double> lock_angle(const mjModel* m, int joint) {
  for (int e = 0; e < m->neq; ++e) {
    if (m->eq_type[e] == mjEQ_JOINT && m->eq_active[e] && m->eq_obj1id[e] == joint &&
        m->eq_obj2id[e] < 0) {
      return m->qpos0[m->jnt_qposadr[joint]] + m->eq_data[e * mjNEQDATA];
    }
  }
  return std::nullopt;
}

class Positional final : public Actuation {
 public:
  explicit Positional(const mjModel* m) : ids_(mimo_actuators(m)) {
    const int n = static_cast<int>(ids_.size());
    space_ = Box{.shape = {n}, .dtype = DType::kFloat32};
    for (int id : ids_) {
      const int joint = actuated_joint(m, id);
      // Position servos: force = kp · (ctrl − q).
      const double kp = m->actuator_gainprm[id * mjNGAIN];
      require_actuator(m->actuator_dyntype[id] == mjDYN_NONE &&
                           m->actuator_gaintype[id] == mjGAIN_FIXED &&
                           m->actuator_biastype[id] == mjBIAS_AFFINE && kp > 0 &&
                           m->actuator_biasprm[id * mjNBIAS + 1] == -kp,
                       m, id, kKind, "is not a position servo");
      require_actuator(m->jnt_limited[joint], m, id, kKind, "drives a joint without a range");
      const double lo = m->jnt_range[2 * joint];
      const double hi = m->jnt_range[2 * joint + 1];
      space_.low.push_back(lo);
      space_.high.push_back(hi);
      const std::optional<double> lock = lock_angle(m, joint);
      locked_.push_back(lock.has_value());
      lock_target_.push_back(lock.value_or(0.0));
    }
  }

  const Box& action_space() const override { return space_; }

  void apply(std::span<const double> action, mjData* d) override {
    if (action.size() != ids_.size()) {
      throw std::invalid_argument("positional action has the wrong size");
    }
    // Clip each target into its joint range; locked joints keep the lock angle.
    for (size_t i = 0; i < ids_.size(); ++i) {
      const double target = locked_[i] ? lock_target_[i] : action[i];
      d->ctrl[ids_[i]] = std::clamp(target, space_.low[i], space_.high[i]);
    }
  }

  int observation_size() const override { return static_cast<int>(ids_.size()); }

  void observe(const mjData* d, std::span<double> out) const override {
    // The servo targets.
    for (size_t i = 0; i < ids_.size(); ++i) out[i] = d->ctrl[ids_[i]];
  }

  double cost() const override { return 0; }

  void reset(mjData* d) override {
    // Zero targets, clipped into range.
    for (size_t i = 0; i < ids_.size(); ++i) {
      const double target = locked_[i] ? lock_target_[i] : 0.0;
      d->ctrl[ids_[i]] = std::clamp(target, space_.low[i], space_.high[i]);
    }
  }

 private:
  std::vector<int> ids_;             // act:* actuators in action order
  std::vector<bool> locked_;         // joint held by an active lock equality
  std::vector<double> lock_target_;  // its lock angle
  Box space_;
};

}  // namespace

std::unique_ptr<Actuation> make_positional(const mjModel* m) {
  return std::make_unique<Positional>(m);
}

}  // namespace cradle::sim

// Spring-damper actuation (mimo_core.md §3.1): the action is the motor control, clipped to the
// motor's force range; the joint torque is gear × control. The spring and damper are the joints'
// own passive stiffness and damping.
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "sim/actuation.h"

namespace cradle::sim {
namespace {

constexpr ActuationModel kKind = ActuationModel::kSpringDamper;

class SpringDamper final : public Actuation {
 public:
  explicit SpringDamper(const mjModel* m) : ids_(mimo_actuators(m)) {
    const int n = static_cast<int>(ids_.size());
    space_ = Box{.shape = {n}, .dtype = DType::kFloat32};
    // Motors with unit gain and no bias; the force range bounds the action.
    for (int id : ids_) {
      actuated_joint(m, id);
      require_actuator(
          m->actuator_dyntype[id] == mjDYN_NONE && m->actuator_gaintype[id] == mjGAIN_FIXED &&
              m->actuator_biastype[id] == mjBIAS_NONE && m->actuator_gainprm[id * mjNGAIN] == 1,
          m, id, kKind, "is not a motor");
      require_actuator(m->actuator_forcelimited[id], m, id, kKind,
                       "is not force-limited (scene composed for another actuation model?)");
      const double lo = m->actuator_forcerange[2 * id];
      const double hi = m->actuator_forcerange[2 * id + 1];
      require_actuator(lo < hi, m, id, kKind, "has an empty force range");
      space_.low.push_back(lo);
      space_.high.push_back(hi);
      gear_.push_back(m->actuator_gear[id * 6]);
    }
    // Normaliser of the cost: n × Σ gear.
    double gear_sum = 0;
    for (double g : gear_) gear_sum += g;
    cost_scale_ = n > 0 && gear_sum != 0 ? 1.0 / (n * gear_sum) : 0.0;
    control_.assign(n, 0.0);
  }

  const Box& action_space() const override { return space_; }

  void apply(std::span<const double> action, mjData* d) override {
    if (action.size() != control_.size()) {
      throw std::invalid_argument("spring-damper action has the wrong size");
    }
    // Clip into the force range; MuJoCo then applies gear × ctrl to the joint.
    for (size_t i = 0; i < control_.size(); ++i) {
      control_[i] = std::clamp(action[i], space_.low[i], space_.high[i]);
      d->ctrl[ids_[i]] = control_[i];
    }
  }

  int observation_size() const override { return 2 * static_cast<int>(ids_.size()); }

  void observe(const mjData* d, std::span<double> out) const override {
    // [clipped action (n), applied torque gear × ctrl (n)].
    const size_t n = ids_.size();
    for (size_t i = 0; i < n; ++i) {
      out[i] = control_[i];
      out[n + i] = gear_[i] * d->ctrl[ids_[i]];
    }
  }

  double cost() const override {
    // Σ |u² G| / (n Σ G): squared controls weighted by each motor's torque scale.
    double sum = 0;
    for (size_t i = 0; i < control_.size(); ++i) {
      sum += std::abs(control_[i] * control_[i] * gear_[i]);
    }
    return sum * cost_scale_;
  }

  void reset(mjData* d) override {
    // A zero action, clipped like any other.
    for (size_t i = 0; i < control_.size(); ++i) {
      control_[i] = std::clamp(0.0, space_.low[i], space_.high[i]);
      d->ctrl[ids_[i]] = control_[i];
    }
  }

 private:
  std::vector<int> ids_;         // act:* actuators in action order
  std::vector<double> gear_;     // per actuator
  std::vector<double> control_;  // last clipped action
  double cost_scale_ = 0;
  Box space_;
};

}  // namespace

std::unique_ptr<Actuation> make_spring_damper(const mjModel* m) {
  return std::make_unique<SpringDamper>(m);
}

}  // namespace cradle::sim

// Proprioception: joint angles, velocities, limit proximity, torque sensors and the actuation
// state, concatenated as the reference does: [actuation | limits | qpos | qvel | torques]. Each
// optional part can be switched off (proprio_* config keys), which the reference ignores.
#pragma once

#include <mujoco/mujoco.h>

#include <span>
#include <string>
#include <vector>

#include "core/spaces.h"
#include "sim/actuation.h"

namespace cradle::senses {

struct ProprioOptions {
  bool velocity = true;
  bool torque = true;
  bool limits = true;
  bool actuation = true;
  double threshold = 0.035;  // rad: limit sensing ramps from 0 to 1 over this distance
};

class Proprioception {
 public:
  Proprioception(const mjModel* m, const ProprioOptions& options, int actuation_size);
  int size() const { return size_; }
  Box space() const { return Box::unbounded({size_}, DType::kFloat64); }
  void read(const mjModel* m, const mjData* d, const sim::Actuation& actuation,
            std::span<double> out) const;
  const std::vector<std::string>& joint_names() const { return joint_names_; }
  const std::vector<std::string>& sensor_names() const { return sensor_names_; }

 private:
  ProprioOptions options_;
  std::vector<int> qpos_adr_, dof_adr_;      // robot:* joints
  std::vector<double> range_lo_, range_hi_;  // their limits (rad)
  std::vector<int> sensor_adr_;              // proprio:* torque sensors (3 values each)
  std::vector<std::string> joint_names_, sensor_names_;
  int actuation_size_ = 0;
  int size_ = 0;
};

// Limit proximity of one joint: 0 while more than `threshold` from both limits, rising linearly to
// 1 at a limit and beyond 1 past it.
double limit_proximity(double q, double lo, double hi, double threshold);

}  // namespace cradle::senses

// Vestibular sense: the head's linear acceleration (with the gravity reaction, m/s²) and angular
// velocity (rad/s) in the head frame, from the accelerometer and gyro on the "vestibular" site.
#pragma once

#include <mujoco/mujoco.h>

#include <span>

#include "core/spaces.h"

namespace cradle::senses {

class Vestibular {
 public:
  explicit Vestibular(const mjModel* m);  // throws std::runtime_error if the sensors are missing
  static constexpr int kSize = 6;
  Box space() const { return Box::unbounded({kSize}, DType::kFloat64); }
  void read(const mjData* d, std::span<double> out) const;

 private:
  int acc_adr_ = -1;
  int gyro_adr_ = -1;
};

}  // namespace cradle::senses

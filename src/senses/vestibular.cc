#include "senses/vestibular.h"

#include <stdexcept>

namespace cradle::senses {

Vestibular::Vestibular(const mjModel* m) {
  const int acc = mj_name2id(m, mjOBJ_SENSOR, "vestibular_acc");
  const int gyro = mj_name2id(m, mjOBJ_SENSOR, "vestibular_gyro");
  if (acc < 0 || gyro < 0) throw std::runtime_error("model has no vestibular sensors");
  acc_adr_ = m->sensor_adr[acc];
  gyro_adr_ = m->sensor_adr[gyro];
}

void Vestibular::read(const mjData* d, std::span<double> out) const {
  for (int k = 0; k < 3; ++k) {
    out[k] = d->sensordata[acc_adr_ + k];
    out[3 + k] = d->sensordata[gyro_adr_ + k];
  }
}

}  // namespace cradle::senses

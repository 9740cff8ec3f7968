#include "senses/proprioception.h"

#include <algorithm>
#include <string_view>

namespace cradle::senses {

double limit_proximity(double q, double lo, double hi, double threshold) {
  const double r = std::min(q - (lo + threshold), (hi - threshold) - q) / threshold;
  return std::max(0.0, -r);
}

Proprioception::Proprioception(const mjModel* m, const ProprioOptions& options, int actuation_size)
    : options_(options), actuation_size_(options.actuation ? actuation_size : 0) {
  for (int j = 0; j < m->njnt; ++j) {
    const char* name = mj_id2name(m, mjOBJ_JOINT, j);
    if (!name || !std::string_view(name).starts_with("robot:")) continue;
    joint_names_.emplace_back(name);
    qpos_adr_.push_back(m->jnt_qposadr[j]);
    dof_adr_.push_back(m->jnt_dofadr[j]);
    range_lo_.push_back(m->jnt_range[2 * j]);
    range_hi_.push_back(m->jnt_range[2 * j + 1]);
  }
  for (int s = 0; s < m->nsensor; ++s) {
    const char* name = mj_id2name(m, mjOBJ_SENSOR, s);
    if (!name || !std::string_view(name).starts_with("proprio:")) continue;
    sensor_names_.emplace_back(name);
    sensor_adr_.push_back(m->sensor_adr[s]);
  }
  const int nj = static_cast<int>(joint_names_.size());
  size_ = actuation_size_ + (options.limits ? nj : 0) + nj + (options.velocity ? nj : 0) +
          (options.torque ? 3 * static_cast<int>(sensor_adr_.size()) : 0);
}

void Proprioception::read(const mjModel*, const mjData* d, const sim::Actuation& actuation,
                          std::span<double> out) const {
  const size_t nj = qpos_adr_.size();
  double* o = out.data();
  // Alphabetical key order of the reference: actuation, limits, qpos, qvel, torques.
  if (actuation_size_ > 0) {
    actuation.observe(d, out.subspan(0, actuation_size_));
    o += actuation_size_;
  }
  if (options_.limits) {
    for (size_t j = 0; j < nj; ++j) {
      *o++ = limit_proximity(d->qpos[qpos_adr_[j]], range_lo_[j], range_hi_[j], options_.threshold);
    }
  }
  for (size_t j = 0; j < nj; ++j) *o++ = d->qpos[qpos_adr_[j]];
  if (options_.velocity) {
    for (size_t j = 0; j < nj; ++j) *o++ = d->qvel[dof_adr_[j]];
  }
  if (options_.torque) {
    for (int adr : sensor_adr_) {
      *o++ = d->sensordata[adr];
      *o++ = d->sensordata[adr + 1];
      *o++ = d->sensordata[adr + 2];
    }
  }
}

}  // namespace cradle::senses

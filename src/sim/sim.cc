#include "sim/sim.h"

#include <algorithm>

#include "core/error.h"
#include "sim/mujoco_handlers.h"

namespace cradle::sim {

Sim::Sim(const mjModel* m, ActuationModel kind, int frame_skip)
    : m_(m),
      d_((install_mujoco_handlers(), mj_makeData(m))),
      actuation_(make_actuation(kind, m)),
      frame_skip_(frame_skip) {
  if (!d_) throw UserError("MuJoCo: cannot allocate the simulation data (out of memory?)");
  reset();
}

void Sim::step(std::span<const double> action) {
  actuation_->apply(action, d_.get());
  for (int i = 0; i < frame_skip_; ++i) {
    actuation_->substep(d_.get());
    mj_step(m_, d_.get());
  }
}

void Sim::reset() {
  mj_resetData(m_, d_.get());
  actuation_->reset(d_.get());
  mj_forward(m_, d_.get());
}

void Sim::save(State& s) const {
  const mjData* d = d_.get();
  s.time = d->time;
  s.qpos.assign(d->qpos, d->qpos + m_->nq);
  s.qvel.assign(d->qvel, d->qvel + m_->nv);
  s.act.assign(d->act, d->act + m_->na);
  s.ctrl.assign(d->ctrl, d->ctrl + m_->nu);
  s.qacc_warmstart.assign(d->qacc_warmstart, d->qacc_warmstart + m_->nv);
}

void Sim::restore(const State& s) {
  mjData* d = d_.get();
  d->time = s.time;
  std::copy(s.qpos.begin(), s.qpos.end(), d->qpos);
  std::copy(s.qvel.begin(), s.qvel.end(), d->qvel);
  std::copy(s.act.begin(), s.act.end(), d->act);
  std::copy(s.ctrl.begin(), s.ctrl.end(), d->ctrl);
  std::copy(s.qacc_warmstart.begin(), s.qacc_warmstart.end(), d->qacc_warmstart);
  mj_forward(m_, d);
}

}  // namespace cradle::sim

#include "sim/sim.h"

#include <algorithm>
#include <cctype>
#include <string>

#include "core/error.h"
#include "sim/mujoco_handlers.h"

namespace cradle::sim {
namespace {

// Overflow warnings MuJoCo has counted in d since its last reset.
int overflow_warnings(const mjData* d) {
  return d->warning[mjWARN_CONTACTFULL].number + d->warning[mjWARN_CNSTRFULL].number;
}

// MuJoCo's warnings of a position, velocity or acceleration that is NaN or huge, after which it
// resets d to the model's initial state (and counts the warning anew from 1).
constexpr int kDivergenceWarnings[] = {mjWARN_BADQPOS, mjWARN_BADQVEL, mjWARN_BADQACC};

// MuJoCo 2.2.2 reports a stack overflow as an error ("... stack ...").
bool is_stack_overflow(const UserError& e) {
  std::string text = e.what();
  for (char& ch : text) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return text.find("stack") != std::string::npos;
}

}  // namespace

Sim::Sim(const mjModel* m, ActuationModel kind, int frame_skip)
    : m_(m),
      d_((install_mujoco_handlers(), mj_makeData(m))),
      actuation_(make_actuation(kind, m)),
      frame_skip_(frame_skip) {
  if (!d_) throw UserError("MuJoCo: cannot allocate the simulation data (out of memory?)");
  reset();
}

void Sim::step(std::span<const double> action) {
  mjData* d = d_.get();
  overflows_ = 0;
  divergences_ = 0;
  actuation_->apply(action, d);
  for (int i = 0; i < frame_skip_ && overflows_ == 0 && divergences_ == 0; ++i) {
    actuation_->substep(d);
    const int before = overflow_warnings(d);
    // The reset after a divergence sets its count back to 1, so a count carried over from an
    // earlier divergence would hide this one: start from 0.
    for (const int w : kDivergenceWarnings) d->warning[w].number = 0;
    try {
      mj_step(m_, d);
    } catch (const UserError& e) {
      if (!is_stack_overflow(e)) throw;
      d->pstack = 0;  // the aborted step's stack frames
      ++overflows_;
    }
    // MuJoCo's reset after a divergence also zeroes the overflow counts: compare nothing then.
    if (std::ranges::any_of(kDivergenceWarnings, [d](int w) { return d->warning[w].number > 0; })) {
      ++divergences_;
    } else {
      overflows_ += overflow_warnings(d) - before;
    }
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

// What an env gives MuJoCo before each mj_step of its data (the controls and, optionally, the
// applied joint forces), recorded through MuJoCo's control callback, and replayed on a bare mjData
// of the same model: the bare loop of `cradle bench` and `cradle sami bench`. One recorder is
// active at a time (the callback is global); recording and replaying allocate nothing.
#pragma once

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cstring>
#include <vector>

namespace cradle {

class MjReplay {
 public:
  // Room for `max_substeps` mj_steps per segment.
  MjReplay(const mjModel* m, long max_substeps, bool applied_forces)
      : nu_(m->nu),
        nv_(applied_forces ? m->nv : 0),
        stride_(m->opt.integrator == mjINT_RK4 ? 4 : 1),
        capacity_(max_substeps),
        ctrl_(static_cast<size_t>(max_substeps * nu_)),
        qfrc_(static_cast<size_t>(max_substeps * nv_)) {}
  MjReplay(const MjReplay&) = delete;
  MjReplay& operator=(const MjReplay&) = delete;
  ~MjReplay() { end(); }

  // A segment starts: the bare data takes the env's whole state, and every later mj_step of the
  // env's data records its inputs until end().
  void begin(const mjModel* m, const mjData* env, mjData* bare) {
    mj_copyData(bare, m, env);
    target_ = env;
    substeps_ = 0;
    calls_ = 0;
    complete_ = true;
    active_ = this;
    mjcb_control = &MjReplay::record;
  }
  void end() {
    if (active_ != this) return;
    mjcb_control = nullptr;
    active_ = nullptr;
  }
  // The recorded inputs, one mj_step each, on the bare data.
  void replay(const mjModel* m, mjData* bare) const {
    for (long i = 0; i < substeps_; ++i) {
      std::copy_n(ctrl_.data() + i * nu_, nu_, bare->ctrl);
      if (nv_ > 0) std::copy_n(qfrc_.data() + i * nv_, nv_, bare->qfrc_applied);
      mj_step(m, bare);
    }
  }
  long substeps() const { return substeps_; }
  // False when the segment had more mj_steps than the recorder has room for.
  bool complete() const { return complete_; }

  // Bitwise equality of the physics state: time, positions, velocities, actuator states.
  static bool same_state(const mjModel* m, const mjData* a, const mjData* b) {
    const auto same = [](const mjtNum* x, const mjtNum* y, int n) {
      return n == 0 || std::memcmp(x, y, sizeof(mjtNum) * static_cast<size_t>(n)) == 0;
    };
    return same(&a->time, &b->time, 1) && same(a->qpos, b->qpos, m->nq) &&
           same(a->qvel, b->qvel, m->nv) && same(a->act, b->act, m->na);
  }

 private:
  // MuJoCo calls this in every mj_forward, just before it reads the controls: once per mj_step,
  // four times with the RK4 integrator (its later stages see the same inputs).
  static void record(const mjModel*, mjData* d) {
    MjReplay* r = active_;
    if (r == nullptr || d != r->target_ || r->calls_++ % r->stride_ != 0) return;
    if (r->substeps_ == r->capacity_) {
      r->complete_ = false;
      return;
    }
    std::copy_n(d->ctrl, r->nu_, r->ctrl_.data() + r->substeps_ * r->nu_);
    if (r->nv_ > 0) std::copy_n(d->qfrc_applied, r->nv_, r->qfrc_.data() + r->substeps_ * r->nv_);
    ++r->substeps_;
  }

  static inline MjReplay* active_ = nullptr;
  int nu_, nv_, stride_;
  long capacity_;
  std::vector<mjtNum> ctrl_, qfrc_;
  const mjData* target_ = nullptr;
  long substeps_ = 0, calls_ = 0;
  bool complete_ = true;
};

}  // namespace cradle

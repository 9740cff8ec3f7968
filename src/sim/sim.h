// One simulation over a shared, read-only compiled model: its own mjData, its actuation model and
// frame skip. Locks live in the model (active from compile time), so nothing here changes them.
#pragma once

#include <mujoco/mujoco.h>

#include <memory>
#include <span>
#include <vector>

#include "core/config.h"
#include "sim/actuation.h"

namespace cradle::sim {

struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
using DataPtr = std::unique_ptr<mjData, DataDeleter>;

// Physics state needed to restart from a moment: time, positions, velocities, actuator states,
// controls and warm-start accelerations.
struct State {
  double time = 0;
  std::vector<double> qpos, qvel, act, ctrl, qacc_warmstart;
};

class Sim {
 public:
  Sim(const mjModel* m, ActuationModel kind, int frame_skip);

  const mjModel* model() const { return m_; }
  mjData* data() { return d_.get(); }
  const mjData* data() const { return d_.get(); }
  Actuation& actuation() { return *actuation_; }
  const Actuation& actuation() const { return *actuation_; }
  int frame_skip() const { return frame_skip_; }
  double dt() const { return frame_skip_ * m_->opt.timestep; }

  // One env step: the action once, then frame_skip physics substeps. A substep that overflows
  // MuJoCo's preallocated sizes (contacts beyond nconmax, constraint rows beyond njmax: MuJoCo
  // drops them and warns; the stack: MuJoCo errors mid-step) ends the step early, its physics
  // wrong, and is counted in overflows() for the caller to end the episode. A substep that
  // diverges (NaN or huge positions, velocities or accelerations: MuJoCo warns and resets the
  // data to the model's initial state mid-episode) ends the step too, counted in divergences().
  void step(std::span<const double> action);
  // Overflows in the last step() (0 when its physics is right).
  int overflows() const { return overflows_; }
  // Divergences in the last step() (0 or 1; 0 when its physics is right).
  int divergences() const { return divergences_; }
  // mj_resetData and a zero action.
  void reset();

  void save(State& state) const;
  // Restores a saved state and recomputes derived quantities (mj_forward).
  void restore(const State& state);

 private:
  const mjModel* m_;
  DataPtr d_;
  std::unique_ptr<Actuation> actuation_;
  int frame_skip_;
  int overflows_ = 0;
  int divergences_ = 0;
};

}  // namespace cradle::sim

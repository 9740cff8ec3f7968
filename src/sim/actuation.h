// Actuation models: how an action vector becomes joint torques. Each env owns its own instance
// (the muscle model keeps per-env activation state); the compiled model is only read.
#pragma once

#include <mujoco/mujoco.h>

#include <memory>
#include <span>
#include <string_view>
#include <vector>

#include "core/config.h"
#include "core/spaces.h"

namespace cradle::sim {

class Actuation {
 public:
  virtual ~Actuation() = default;
  // float32 Box, one entry per action dimension.
  virtual const Box& action_space() const = 0;
  // Once per env step, before the physics substeps: clips the action and sets controls/targets.
  virtual void apply(std::span<const double> action, mjData* d) = 0;
  // Before every physics substep (the muscle model integrates its state here).
  virtual void substep(mjData* d) { (void)d; }
  // The actuation part of proprioception.
  virtual int observation_size() const = 0;
  virtual void observe(const mjData* d, std::span<double> out) const = 0;
  // Effort cost of the current action (see each model for its formula).
  virtual double cost() const = 0;
  // After mj_resetData: back to a zero action.
  virtual void reset(mjData* d) = 0;
};

// The model's act:* actuators driven by the chosen actuation model. Expects a model composed for
// that actuation model (scene/compose.h): motors for spring-damper; unclamped motors on joints with
// zero stiffness and damping/20 for muscle; position servos for positional.
// Throws std::runtime_error when the act:* actuators do not fit the kind (e.g. limited motors for
// the muscle model, position servos for spring-damper).
std::unique_ptr<Actuation> make_actuation(ActuationModel kind, const mjModel* m);

// The three models behind make_actuation, each checking the model as described there.
std::unique_ptr<Actuation> make_spring_damper(const mjModel* m);
std::unique_ptr<Actuation> make_muscle(const mjModel* m);
std::unique_ptr<Actuation> make_positional(const mjModel* m);

// Ids of the actuators named act:* in model order (the order of the action vector).
std::vector<int> mimo_actuators(const mjModel* m);

// The hinge or slide joint that an actuator drives; throws std::runtime_error for any other
// transmission.
int actuated_joint(const mjModel* m, int actuator);

// Model checks: throws std::runtime_error("<kind> actuation: <actuator name> <problem>") unless ok.
void require_actuator(bool ok, const mjModel* m, int actuator, ActuationModel kind,
                      std::string_view problem);

}  // namespace cradle::sim

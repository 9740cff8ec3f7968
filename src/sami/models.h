// SaMI model generation: the MJCF of each SaMI robot built in code from the facts of
// shared/spec/sami_models.md, and its compilation into one shared, read-only mjModel.
#pragma once

#include <mujoco/mujoco.h>

#include <memory>
#include <string>
#include <string_view>

#include "sami/envs/registry.h"

namespace cradle::sami {

// The robots of the registration table (sami/envs/registry.h), in its order.
enum class Robot {
#define CRADLE_SAMI_ROBOT_ENUMERATOR(robot) robot,
  CRADLE_SAMI_ROBOTS(CRADLE_SAMI_ROBOT_ENUMERATOR)
#undef CRADLE_SAMI_ROBOT_ENUMERATOR
};

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
using ModelPtr = std::shared_ptr<const mjModel>;

// The MJCF text of a robot. Every model has a tracking camera named "track" for pictures.
std::string robot_xml(Robot robot);
// Compiles robot_xml(robot); throws std::runtime_error if MuJoCo refuses it (a bug, not user
// input).
ModelPtr compile_robot(Robot robot);
// Compiles any MJCF text (used by tests with tiny inline models).
ModelPtr compile_xml(std::string_view xml);

}  // namespace cradle::sami

// What one SaMI env file (sami/envs/<env>.cc) defines: the env's definition, everything the
// family knows of the env in one place (EnvPool's one header per env). Its line in the
// registration table (envs/registry.h) makes the EnvId and puts the definition in env_def()'s
// table, which env_name, env_from_name, env_spec, env_varies, split_sets, make_env and
// robot_xml read. Below it the helpers the env files share: task-set shapes and MJCF pieces.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/xml.h"
#include "sami/env.h"
#include "sami/envs/registry.h"
#include "sami/locomotion.h"
#include "sami/models.h"
#include "sami/task.h"

namespace cradle::sami {

using MakeEnv = std::unique_ptr<SamiEnv> (*)(Spec spec, ModelPtr model, std::vector<TaskSet> sets,
                                             std::uint64_t seed, Options options);

struct EnvDef {
  std::string_view name;  // EnvId's name, the reference's: "CrippleHalfCheetah"
  Robot robot{};
  // The robot's MJCF text (robot_xml); given by one env of each robot (the one without a prefix),
  // which the others of that robot start from.
  std::string (*model)() = nullptr;
  // The spec (sami/env.h).
  int obs_size = 0, action_size = 0;
  double action_low = -1, action_high = 1;
  int horizon = 0, frame_skip = 0;
  double dt = 0;
  std::vector<ObsKey> keys;  // empty: one "observation" key of obs_size values
  // The hidden parameters: what a task set may vary, and the built-in task sets of each split.
  Varies varies;
  std::vector<TaskSet> (*split_sets)(Split split) = nullptr;
  // The step: a locomotion env's rules on the shared mechanics (sami/locomotion.h), or, when
  // `make` is set, an env class of its own (Panda).
  LocomotionDef locomotion;
  MakeEnv make = nullptr;
};

// The definition of a registered env (the registration table's).
const EnvDef& env_def(EnvId id);

// The env files' definitions, one per line of the registration table.
namespace envs {
#define CRADLE_SAMI_ENV_DECLARATION(id, file) const EnvDef& file();
CRADLE_SAMI_ENVS(CRADLE_SAMI_ENV_DECLARATION)
#undef CRADLE_SAMI_ENV_DECLARATION
}  // namespace envs

// Task-set shapes (sami/task.cc).
using Values = std::vector<double>;
using Cripples = std::vector<std::vector<int>>;
// The four mass x damping quadrants of a low and a high value list.
std::vector<TaskSet> quadrants(const Values& low, const Values& high);
// Cripple envs: one set per mass group, each with the same cripple choices.
std::vector<TaskSet> mass_groups(const std::vector<Values>& groups, const Cripples& cripple,
                                 bool mask = true);
// Every pair {a, b} with a from `first` and b from `second`, ascending.
Cripples pairs(const std::vector<int>& first, const std::vector<int>& second);
Cripples singles(const std::vector<int>& units);
// The mass groups of the cripple envs' splits.
inline const Values kTrainMass = {0.75, 0.85, 1.0, 1.15, 1.25};
inline const std::vector<Values> kModerateMass = {{0.4, 0.5}, {1.5, 1.6}};
inline const std::vector<Values> kExtremeMass = {{0.2, 0.3}, {1.7, 1.8}};

// MJCF pieces the robots share (sami/models.cc).
// A light from above and a chequered floor material.
void scenery(XmlWriter& x);
void light(XmlWriter& x);
// A tracking camera beside the robot, looking at it horizontally (pitch 0) or from above.
void track_camera(XmlWriter& x, double distance, double height, bool from_above = false);
// The actuator section: a motor per joint, named after it, with its gear.
void gear_motors(XmlWriter& x,
                 std::initializer_list<std::pair<const char*, const char*>> joint_gears);
// Hopper (§1.3) or Walker2d (§1.4), one builder for the two planar robots.
std::string planar_robot(bool walker);

}  // namespace cradle::sami

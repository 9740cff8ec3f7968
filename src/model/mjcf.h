// MJCF emitter: turns the infant tables into the XML sections of a MuJoCo model. The composer
// (scene/compose.h) places the sections into one self-contained scene file.
#pragma once

#include <map>
#include <optional>
#include <set>
#include <string>

#include "core/config.h"
#include "core/groups.h"
#include "model/infant.h"

namespace cradle::model {

struct EmitOptions {
  ActuationModel actuation = ActuationModel::kSpringDamper;
  GroupFlags act_groups = GroupFlags::all(true);    // groups whose actuators exist
  GroupFlags lock_groups = GroupFlags::all(false);  // groups whose joint locks start active
  // Joints the scene already pins with its own equality: their lock stays inactive, as in the
  // reference (which skips a lock when another active joint equality names the joint).
  std::set<std::string> scene_constrained_joints;
  // Only these actuators and torque sensors (names without prefix) when set, e.g. a sample scene's
  // right arm; the act_groups filter applies as well.
  std::optional<std::set<std::string>> actuators;
  std::optional<std::set<std::string>> torque_sensors;
  // Joints whose lock starts active at the given angle (rad) instead of 0, whatever their group.
  std::map<std::string, double> lock_angles;
};

// Proportional gain of positional actuators, per unit of actuator gear (N·m per rad per N·m):
// a 0.1 rad error commands the joint's full strength.
inline constexpr double kPositionalGainPerGear = 10.0;

struct InfantXml {
  std::string defaults;  // <default class="mimo"> ... </default>
  std::string body;      // <body name="hip" childclass="mimo"> ... (goes inside mimo_location)
  std::string contact;   // <pair>, <exclude>
  std::string tendon;    // <fixed> ...
  std::string sensor;    // vestibular accelerometer + gyro, then proprio: torque sensors
  std::string actuator;  // act:* motors or position servos, in group order
  std::string equality;  // one robot:* joint lock per joint
};

InfantXml emit_infant(const Infant& infant, const EmitOptions& options);

// Prefixes MuJoCo names carry in the generated model.
inline constexpr const char* kJointPrefix = "robot:";
inline constexpr const char* kActuatorPrefix = "act:";
inline constexpr const char* kTorquePrefix = "proprio:";

}  // namespace cradle::model

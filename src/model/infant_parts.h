// Building blocks shared by the v1 and v2 tables (internal to src/model).
#pragma once

#include <functional>
#include <string>
#include <vector>

#include "model/infant.h"

namespace cradle::model {

enum class Side { kRight, kLeft };
inline std::string side_prefix(Side side) { return side == Side::kRight ? "right_" : "left_"; }
inline const char* side_name(Side side) { return side == Side::kRight ? "right" : "left"; }

Geom sphere(std::string name, double radius, Vec3 pos, double mass, std::string material);
Geom capsule(std::string name, std::vector<double> size, Vec3 pos, Vec3 euler, double mass,
             std::string material);
Geom cylinder(std::string name, std::vector<double> size, Vec3 pos, Vec3 euler, double mass,
              std::string material);
Geom box(std::string name, std::vector<double> size, Vec3 pos, Vec3 euler, double mass,
         std::string material);
// A hinge; range and springref in degrees.
Joint hinge(std::string name, Vec3 axis, Vec3 pos, double lo, double hi, double springref,
            double stiffness, double damping, double frictionloss, double armature);

// Masses that v2 re-tuned (kg); the defaults are v1's.
struct TrunkMasses {
  double lb = 1.1584, cb = 1.3245, ub1 = 1.0882, ub2 = .9499, ub3 = .7217, head = 1.7748;
  double eye = .006275;
};
struct LegMasses {
  double thigh = .7998, shank1 = .3341, shank2 = .1160;
};

// hip, lower_body, upper_body, head and both eyes (with their cameras).
void add_trunk_and_head(Infant& infant, const TrunkMasses& masses);
// Upper and lower arm of one side.
void add_arm(Infant& infant, Side side, double upper_mass, double lower_mass);
// Upper and lower leg of one side.
void add_leg(Infant& infant, Side side, const LegMasses& masses);
// Soles and toes grip twice as hard as skin (sliding, torsional, rolling friction).
inline constexpr Vec3 kSoleGrip{2, 0.02, 0.01};
// The foot body of one side below its lower leg, `geoms` being its heel cylinder, sole box and
// ball cylinder (the last two gripping with kSoleGrip), with the three ankle hinges and their
// torque site.
void add_foot_body(Infant& infant, Side side, std::vector<Geom> geoms);

// Every actuator in BabyBench group order: body, head, eyes, arms, hands, the fingers of each side
// (`add_fingers`, the version's), legs, then each side's ankle followed by its toes (`add_toes`,
// the version's); right side before left.
void add_actuators(Infant& infant, const std::function<void(Side)>& add_fingers,
                   const std::function<void(Side)>& add_toes);

// Every torque sensor in the reference's sensordata order: head, eyes and trunk, then the arms'
// and then the legs' joints, right side before left, each side's in the order of `arm_joints` /
// `leg_joints` (sites "torque_<side>_<joint>").
void add_torque_sensors(Infant& infant, const std::vector<std::string>& arm_joints,
                        const std::vector<std::string>& leg_joints);
// Trunk-coupling and head-limit tendons, the hip/torso contact pair and eye exclusions.
void add_tendons_and_contacts(Infant& infant);

}  // namespace cradle::model

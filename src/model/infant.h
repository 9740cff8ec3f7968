// The MIMo infant as plain tables: bodies, joints, geoms, sites, actuators, sensors, tendons.
// Values follow the reference MJCF (lengths in metres, angles in degrees as written there, masses
// in kg); the MJCF emitter (mjcf.h) turns these tables into XML.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/groups.h"

namespace cradle::model {

using Vec3 = std::array<double, 3>;

enum class MimoVersion { kV1, kV2 };

enum class GeomType { kSphere, kCapsule, kBox, kCylinder };
std::string_view geom_type_name(GeomType type);

struct Geom {
  std::string name;  // empty: unnamed, as in the reference
  GeomType type = GeomType::kSphere;
  std::vector<double> size;  // MuJoCo size: sphere {r}, capsule/cylinder {r, half-length}, box {3}
  Vec3 pos{0, 0, 0};
  Vec3 euler{0, 0, 0};  // degrees, MuJoCo's default xyz sequence
  double mass = 0;
  std::optional<Vec3> friction;  // unset: the class default (1 0.005 0.0002)
  int contype = 1;
  int conaffinity = 1;
  int condim = 0;        // 0: the class default (3)
  std::string material;  // empty: the class default (skin)
};

struct Joint {
  std::string name;  // without the "robot:" prefix
  Vec3 axis{0, 0, 1};
  Vec3 pos{0, 0, 0};
  double range_lo = 0;   // degrees
  double range_hi = 0;   // degrees
  double springref = 0;  // degrees
  double stiffness = 0;
  double damping = 0;
  double frictionloss = 0;
  double armature = 0;
};

struct Site {
  std::string name;
  Vec3 pos{0, 0, 0};
  double radius = 0.01;
};

struct Camera {
  std::string name;
  Vec3 pos{0, 0, 0};
  Vec3 euler{0, 0, 0};  // degrees
  double fovy = 45;     // degrees
};

struct Body {
  std::string name;
  std::string parent;  // empty for the root of the infant (hip)
  Vec3 pos{0, 0, 0};
  Vec3 euler{0, 0, 0};  // degrees
  std::vector<Geom> geoms;
  std::vector<Joint> joints;
  std::vector<Site> sites;
  std::vector<Camera> cameras;
};

struct Actuator {
  std::string name;   // without the "act:" prefix
  std::string joint;  // without the "robot:" prefix
  cradle::Group group = cradle::Group::kBody;
  double gear = 1;
  double force_lo = -1;
  double force_hi = 1;
  std::array<double, 3> user{0, 0, 0};  // VMAX, FMAX_neg, FMAX_pos for the muscle model
};

// Torque sensor: the interaction torque between the site's body and its parent.
struct TorqueSensor {
  std::string name;  // without the "proprio:" prefix
  std::string site;
};

struct FixedTendon {
  std::string name;
  std::vector<std::pair<std::string, double>> joints;  // joint name (no prefix), coefficient
  double range_lo = 0;
  double range_hi = 0;
};

struct ContactPair {
  std::string geom1;
  std::string geom2;
  int condim = 3;
};

struct ContactExclude {
  std::string body1;
  std::string body2;
};

struct Infant {
  MimoVersion version = MimoVersion::kV1;
  std::vector<Body> bodies;  // parents before children; bodies[0] is "hip"
  std::vector<Actuator> actuators;
  std::vector<TorqueSensor> torque_sensors;
  std::vector<FixedTendon> tendons;
  std::vector<ContactPair> pairs;
  std::vector<ContactExclude> excludes;
};

// Solver parameters of every joint lock (and of the cubes scene's sitting constraints), as stiff
// as MuJoCo allows: impedance at its 0.9999 cap and the shortest time constant it accepts at a
// 5 ms step (2 steps). The reference uses MuJoCo's defaults (v1) or solimp 0.95 0.99999 (v2), under
// which a locked joint sags by up to 0.013 rad; here locked joints stay within 1e-6 rad at rest
// and within about 1.5e-3 rad under full random effort of every other joint.
inline constexpr std::array<double, 5> kLockSolimp = {0.9999, 0.9999, 0.001, 0.5, 2};
inline constexpr std::array<double, 2> kLockSolref = {0.01, 1};

Infant make_mimo_v1();
Infant make_mimo_v2();
Infant make_mimo(MimoVersion version);

// The body-part group a MIMo body belongs to (BabyBench's BODY_GROUPS).
cradle::Group body_group(std::string_view body_name);

// Number of hinge joints, summed over all bodies.
int joint_count(const Infant& infant);
// Joints of the infant in tree (qpos) order, with the body each belongs to.
std::vector<std::pair<const Body*, const Joint*>> joints_in_order(const Infant& infant);

}  // namespace cradle::model

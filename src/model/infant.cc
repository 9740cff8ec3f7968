// Parts of the MIMo tables shared by v1 and v2, and queries over an Infant.
#include "model/infant.h"

#include <utility>

#include "model/infant_parts.h"

namespace cradle::model {

std::string_view geom_type_name(GeomType type) {
  switch (type) {
    case GeomType::kSphere:
      return "sphere";
    case GeomType::kCapsule:
      return "capsule";
    case GeomType::kBox:
      return "box";
    case GeomType::kCylinder:
      return "cylinder";
  }
  return "sphere";
}

Geom sphere(std::string name, double radius, Vec3 pos, double mass, std::string material) {
  return {.name = std::move(name),
          .type = GeomType::kSphere,
          .size = {radius},
          .pos = pos,
          .mass = mass,
          .material = std::move(material)};
}

namespace {
Geom shaped(GeomType type, std::string name, std::vector<double> size, Vec3 pos, Vec3 euler,
            double mass, std::string material) {
  return {.name = std::move(name),
          .type = type,
          .size = std::move(size),
          .pos = pos,
          .euler = euler,
          .mass = mass,
          .material = std::move(material)};
}
}  // namespace

Geom capsule(std::string name, std::vector<double> size, Vec3 pos, Vec3 euler, double mass,
             std::string material) {
  return shaped(GeomType::kCapsule, std::move(name), std::move(size), pos, euler, mass,
                std::move(material));
}
Geom cylinder(std::string name, std::vector<double> size, Vec3 pos, Vec3 euler, double mass,
              std::string material) {
  return shaped(GeomType::kCylinder, std::move(name), std::move(size), pos, euler, mass,
                std::move(material));
}
Geom box(std::string name, std::vector<double> size, Vec3 pos, Vec3 euler, double mass,
         std::string material) {
  return shaped(GeomType::kBox, std::move(name), std::move(size), pos, euler, mass,
                std::move(material));
}

Joint hinge(std::string name, Vec3 axis, Vec3 pos, double lo, double hi, double springref,
            double stiffness, double damping, double frictionloss, double armature) {
  return {.name = std::move(name),
          .axis = axis,
          .pos = pos,
          .range_lo = lo,
          .range_hi = hi,
          .springref = springref,
          .stiffness = stiffness,
          .damping = damping,
          .frictionloss = frictionloss,
          .armature = armature};
}

void add_trunk_and_head(Infant& infant, const TrunkMasses& m) {
  Body hip{.name = "hip", .parent = ""};
  hip.geoms.push_back(capsule("lb", {.048, .043}, {-.002, 0, 0.005}, {90, 0, 0}, m.lb, "pants_up"));
  hip.sites.push_back({.name = "lowerBody_center"});
  infant.bodies.push_back(hip);

  Body lower{.name = "lower_body", .parent = "hip", .pos = {0.002, 0, 0.076}};
  Geom cb = capsule("cb", {.053, .035}, {0.005, 0, -.008}, {90, 0, 0}, m.cb, "top_down");
  cb.contype = 0;
  lower.geoms.push_back(cb);
  lower.joints = {
      hinge("hip_lean1", {1, 0, 0}, {0, 0, -.05}, -14, 14, 0, 3.38, 0.77, .049, 0.01),
      hinge("hip_rot1", {0, 0, 1}, {0, 0, -.05}, -18, 18, 0, 1.45, 0.29, .018, 0.01),
      hinge("hip_bend1", {0, 1, 0}, {0, 0, -.05}, -17, 30.5, 0, 2.20, 0.84, 0.040, 0.01),
  };
  lower.sites.push_back({.name = "torque_lb"});
  infant.bodies.push_back(lower);

  Body upper{.name = "upper_body", .parent = "lower_body", .pos = {-.002, 0, 0.091}};
  upper.geoms = {
      capsule("ub1", {.052, .035}, {0.007, 0, -.032}, {90, 0, 0}, m.ub1, "top_middle"),
      capsule("ub2", {.048, .039}, {0.004, 0, 0.03}, {90, 0, 0}, m.ub2, "top_middle"),
      capsule("ub3", {.041, .047}, {0, 0, 0.09}, {90, 0, 0}, m.ub3, "top_up"),
  };
  upper.joints = {
      hinge("hip_lean2", {1, 0, 0}, {0, 0, -.05}, -27, 27, 0, 1.69, 0.38, .024, 0.01),
      hinge("hip_rot2", {0, 0, 1}, {0, 0, -.05}, -18, 18, 0, 1.45, 0.29, .018, 0.01),
      hinge("hip_bend2", {0, 1, 0}, {0, 0, -.05}, -17, 30.5, 0, 2.20, 0.84, 0.040, 0.01),
  };
  upper.sites.push_back({.name = "torque_ub"});
  infant.bodies.push_back(upper);

  Body head{.name = "head", .parent = "upper_body", .pos = {0, 0, .135}};
  head.geoms.push_back(sphere("head", .0735, {0.01, 0, 0.0735}, m.head, "head"));
  head.joints = {
      hinge("head_swivel", {0, 0, 1}, {0, 0, 0}, -111, 111, 0, .23, .29, .018, 0.005),
      hinge("head_tilt", {0, 1, 0}, {0, 0, 0.0123}, -70, 81, 0, .45, .53, .018, 0.005),
      hinge("head_tilt_side", {1, 0, 0}, {0, 0, 0.0245}, -70, 70, 0, .37, .29, .018, 0.005),
  };
  head.sites = {{.name = "torque_neck"}, {.name = "vestibular", .pos = {0.01, 0, 0.0735}}};
  infant.bodies.push_back(head);

  // Eyes, left then right; the horizontal and torsional axes mirror.
  for (Side side : {Side::kLeft, Side::kRight}) {
    const double s = side == Side::kLeft ? 1 : -1;
    const std::string p = side_prefix(side);
    Body eye{.name = p + "eye", .parent = "head", .pos = {.07, s * .0245, .067375}};
    eye.geoms.push_back(
        sphere("", .01125, {0, 0, 0}, m.eye, "eye_" + std::string(side_name(side))));
    eye.joints = {
        hinge(p + "eye_horizontal", {0, 0, s}, {0, 0, 0}, -45, 45, 0, .00065, .00042, .000054,
              .0002),
        hinge(p + "eye_vertical", {0, -1, 0}, {0, 0, 0}, -47, 33, 0, .00065, .00042, .000054,
              .0002),
        hinge(p + "eye_torsional", {-s, 0, 0}, {0, 0, 0}, -8, 8, 0, .00267, .00042, .000037, .0002),
    };
    eye.sites.push_back({.name = "torque_" + p + "eye"});
    // The camera sits on the eye surface looking along the eye's +x (MuJoCo cameras look along
    // their own -z; euler 90 -90 0 turns that onto +x, with the camera's up on +z).
    eye.cameras.push_back({.name = "eye_" + std::string(side_name(side)),
                           .pos = {0.01125, 0, 0},
                           .euler = {90, -90, 0},
                           .fovy = 60});
    infant.bodies.push_back(eye);
  }
}

void add_arm(Infant& infant, Side side, double upper_mass, double lower_mass) {
  const double s = side == Side::kRight ? 1 : -1;  // left limbs flip some axes
  const std::string p = side_prefix(side);
  Body upper{.name = p + "upper_arm",
             .parent = "upper_body",
             .pos = {-.005, -s * 0.105, .093},
             .euler = {s * 170, 0, 0}};
  upper.geoms.push_back(
      capsule(p + "uarm1", {0.024, 0.0536}, {0, 0, .0536}, {0, 0, 0}, upper_mass, "sleeve"));
  upper.joints = {
      hinge(p + "shoulder_horizontal", {0, 1, -4 * s}, {0, -.024 * s, 0}, -28, 118, 0, .09, .05,
            .0009, 0.004),
      hinge(p + "shoulder_ad_ab", {-s, 0, 0}, {0, 0, 0}, -84, 183, 0, .11, .10, .0014, 0.004),
      hinge(p + "shoulder_rotation", {0, 0, -s}, {0, 0, 0}, -99, 67, 0, .12, .07, .0008, 0.004),
  };
  upper.sites.push_back({.name = "torque_" + p + "shoulder"});
  infant.bodies.push_back(upper);

  Body lower{.name = p + "lower_arm", .parent = p + "upper_arm", .pos = {0, 0, .1076}};
  lower.geoms.push_back(
      capsule(p + "larm", {.023, 0.037}, {0, 0, .037}, {0, 0, 0}, lower_mass, "skin"));
  lower.joints.push_back(
      hinge(p + "elbow", {0, -1, 0}, {0, 0, 0}, -146, 5, -20, .13, .11, .030, 0.002));
  lower.sites.push_back({.name = "torque_" + p + "elbow"});
  infant.bodies.push_back(lower);
}

void add_leg(Infant& infant, Side side, const LegMasses& m) {
  const double s = side == Side::kRight ? 1 : -1;
  const std::string p = side_prefix(side);
  Body upper{.name = p + "upper_leg", .parent = "hip", .pos = {0.005, -s * .051, -.007}};
  // Thighs touch each other and everything else, but not the lower trunk (cb has contype 0).
  Geom thigh = capsule("", {.037, .0625}, {0, 0, -.0645}, {0, 0, 0}, m.thigh, "pants_up");
  thigh.contype = 2;
  thigh.conaffinity = 3;
  upper.geoms.push_back(thigh);
  upper.joints = {
      hinge(p + "hip1", {0, 1, 0}, {0, 0, 0}, -133, 20, -10, 1.72, 1.27, .08, .005),
      hinge(p + "hip2", {s, 0, 0}, {0, 0, 0}, -51, 17, 0, 3.51, 1.99, .062, .005),
      hinge(p + "hip3", {0, 0, -s}, {0, 0, 0}, -32, 41, 0, 2.16, 0.75, .027, .005),
  };
  upper.sites.push_back({.name = "torque_" + p + "hip"});
  infant.bodies.push_back(upper);

  Body lower{.name = p + "lower_leg", .parent = p + "upper_leg", .pos = {0, 0, -.135}};
  lower.geoms = {
      capsule("", {.029, .044}, {0, 0, -.044}, {0, 0, 0}, m.shank1, "pants_down"),
      capsule("", {.021, .028}, {0, 0, -.134}, {0, 0, 0}, m.shank2, "pants_down"),
  };
  lower.joints.push_back(
      hinge(p + "knee", {0, -1, 0}, {0, 0, 0}, -145, 4, -30, 1.63, 0.53, .065, .003));
  lower.sites.push_back({.name = "torque_" + p + "knee"});
  infant.bodies.push_back(lower);
}

void add_foot_body(Infant& infant, Side side, std::vector<Geom> geoms) {
  const double s = side == Side::kRight ? 1 : -1;
  const std::string p = side_prefix(side);
  Body foot{.name = p + "foot", .parent = p + "lower_leg", .pos = {0, 0, -.177}};
  foot.geoms = std::move(geoms);
  foot.geoms[1].friction = kSoleGrip;
  foot.geoms[2].friction = kSoleGrip;
  foot.joints = {
      hinge(p + "foot1", {0, -1, 0}, {0, 0, .015}, -63, 32, -10, 1.29, 0.6, .019, .003),
      hinge(p + "foot2", {s, 0, 0}, {0, 0, .015}, -33, 31, 0, 0.96, 0.37, .011, .0025),
      hinge(p + "foot3", {0, 0, s}, {0, 0, .015}, -20, 30, 0, 1.15, 0.38, .012, .002),
  };
  foot.sites.push_back({.name = "torque_" + p + "ankle"});
  infant.bodies.push_back(foot);
}

namespace {
// One row of the actuator tables: name, joint, gear, force range, muscle user values.
Actuator motor(std::string name, std::string joint, Group group, double gear, double lo, double hi,
               std::array<double, 3> user) {
  return {.name = std::move(name),
          .joint = std::move(joint),
          .group = group,
          .gear = gear,
          .force_lo = lo,
          .force_hi = hi,
          .user = user};
}

void add_body_head_eye_actuators(Infant& infant) {
  auto& a = infant.actuators;
  a.push_back(motor("hip_bend", "hip_bend1", Group::kBody, 10.58, -1, .765, {.8574, 32.93, 22.97}));
  a.push_back(motor("hip_twist", "hip_rot1", Group::kBody, 3.63, -1, 1, {1.699, 8.136, 8.136}));
  a.push_back(motor("hip_lean", "hip_lean1", Group::kBody, 7.25, -1, 1, {1.278, 1.264, 1.264}));
  a.push_back(motor("head_swivel", "head_swivel", Group::kHead, 1.8, -1, 1, {.6665, 24.87, 24.87}));
  a.push_back(motor("head_tilt", "head_tilt", Group::kHead, 3.3, -1, .55, {.9338, 31.39, 16.86}));
  a.push_back(
      motor("head_tilt_side", "head_tilt_side", Group::kHead, 1.8, -1, 1, {1.068, 15.69, 15.69}));
  for (Side side : {Side::kLeft, Side::kRight}) {
    const std::string p = side_prefix(side) + "eye_";
    a.push_back(motor(p + "horizontal", p + "horizontal", Group::kEyes, .0054, -1, 1,
                      {5.110, .03025, .03025}));
    a.push_back(
        motor(p + "vertical", p + "vertical", Group::kEyes, .0054, -1, 1, {6.179, .02619, .02771}));
    a.push_back(motor(p + "torsional", p + "torsional", Group::kEyes, .0037, -1, 1,
                      {25.03, .003686, .003686}));
  }
}

void add_arm_actuators(Infant& infant) {
  for (Side side : {Side::kRight, Side::kLeft}) {
    const std::string p = side_prefix(side);
    auto& a = infant.actuators;
    a.push_back(motor(p + "shoulder_horizontal", p + "shoulder_horizontal", Group::kArms, 1.8, -1,
                      1, {1.811, 18.80, 15.30}));
    a.push_back(motor(p + "shoulder_abduction", p + "shoulder_ad_ab", Group::kArms, 4, -.6875, 1,
                      {.8793, 44.17, 69.23}));
    a.push_back(motor(p + "shoulder_internal", p + "shoulder_rotation", Group::kArms, 2.5, -1, .64,
                      {1.498, 25.09, 17.10}));
    a.push_back(motor(p + "elbow", p + "elbow", Group::kArms, 3.6, -1, .83, {1.566, 35.43, 27.04}));
  }
}

void add_hand_actuators(Infant& infant) {
  for (Side side : {Side::kRight, Side::kLeft}) {
    const std::string p = side_prefix(side);
    auto& a = infant.actuators;
    a.push_back(
        motor(p + "wrist_rotation", p + "hand1", Group::kHands, .7, -1, 1, {1.513, 7.842, 7.842}));
    a.push_back(motor(p + "wrist_flexion", p + "hand2", Group::kHands, 1.24, -1, .57,
                      {1.455, 13.66, 7.874}));
    a.push_back(
        motor(p + "wrist_ulnar", p + "hand3", Group::kHands, .95, -.87, 1, {2.254, 5.155, 6.021}));
  }
}

void add_leg_actuators(Infant& infant) {
  for (Side side : {Side::kRight, Side::kLeft}) {
    const std::string p = side_prefix(side);
    auto& a = infant.actuators;
    a.push_back(motor(p + "hip_flex", p + "hip1", Group::kLegs, 8, -1, 1, {1.083, 71.25, 92.49}));
    a.push_back(
        motor(p + "hip_abduction", p + "hip2", Group::kLegs, 6.24, -1, 1, {1.488, 24.81, 29.20}));
    a.push_back(
        motor(p + "hip_rotation", p + "hip3", Group::kLegs, 3.54, -.75, 1, {1.860, 12.32, 15.78}));
    a.push_back(motor(p + "knee", p + "knee", Group::kLegs, 10, -.65, 1, {1.450, 63.16, 89.27}));
  }
}

void add_ankle_actuators(Infant& infant, Side side) {
  const std::string p = side_prefix(side);
  auto& a = infant.actuators;
  a.push_back(
      motor(p + "foot_flexion", p + "foot1", Group::kFeet, 3.78, -1, .5, {1.430, 21.34, 11.87}));
  a.push_back(
      motor(p + "foot_inversion", p + "foot2", Group::kFeet, 1.16, -.91, 1, {1.988, 4.184, 4.645}));
  a.push_back(
      motor(p + "foot_rotation", p + "foot3", Group::kFeet, 1.2, -1, 1, {2.688, 3.868, 3.625}));
}

}  // namespace

void add_actuators(Infant& infant, const std::function<void(Side)>& add_fingers,
                   const std::function<void(Side)>& add_toes) {
  add_body_head_eye_actuators(infant);
  add_arm_actuators(infant);
  add_hand_actuators(infant);
  for (Side side : {Side::kRight, Side::kLeft}) add_fingers(side);
  add_leg_actuators(infant);
  for (Side side : {Side::kRight, Side::kLeft}) {
    add_ankle_actuators(infant, side);
    add_toes(side);
  }
}

void add_torque_sensors(Infant& infant, const std::vector<std::string>& arm_joints,
                        const std::vector<std::string>& leg_joints) {
  infant.torque_sensors.insert(infant.torque_sensors.end(), {{"neck", "torque_neck"},
                                                             {"left_eye", "torque_left_eye"},
                                                             {"right_eye", "torque_right_eye"},
                                                             {"trunk_upper", "torque_ub"},
                                                             {"trunk_lower", "torque_lb"}});
  for (const std::vector<std::string>* joints : {&arm_joints, &leg_joints}) {
    for (Side side : {Side::kRight, Side::kLeft}) {
      const std::string p = side_prefix(side);
      for (const std::string& joint : *joints) {
        infant.torque_sensors.push_back({p + joint, "torque_" + p + joint});
      }
    }
  }
}

void add_tendons_and_contacts(Infant& infant) {
  // The unactuated upper-trunk joints follow the actuated lower ones within +-0.01 rad.
  infant.tendons = {
      {"hip_bend", {{"hip_bend1", 1}, {"hip_bend2", -1}}, -0.01, 0.01},
      {"hip_rotation", {{"hip_rot1", 1}, {"hip_rot2", -1}}, -0.01, 0.01},
      {"hip_lean", {{"hip_lean1", 1}, {"hip_lean2", -0.5}}, -0.01, 0.01},
  };
  // Combined head rotations are limited to 2.1 rad in each pairing.
  const std::pair<const char*, const char*> head_pairs[] = {{"head_swivel", "head_tilt_side"},
                                                            {"head_tilt", "head_tilt_side"},
                                                            {"head_swivel", "head_tilt"}};
  for (int i = 0; i < 3; ++i) {
    const std::string n = "head_limits" + std::to_string(i + 1);
    infant.tendons.push_back({n, {{head_pairs[i].first, 1}, {head_pairs[i].second, 1}}, -2.1, 2.1});
    infant.tendons.push_back(
        {n + "_sym", {{head_pairs[i].first, 1}, {head_pairs[i].second, -1}}, -2.1, 2.1});
  }
  infant.pairs = {{"lb", "ub1", 1}};
  infant.excludes = {{"left_eye", "upper_body"}, {"right_eye", "upper_body"}};
}

Group body_group(std::string_view name) {
  for (std::string_view prefix : {"left_", "right_"}) {
    if (name.starts_with(prefix)) name.remove_prefix(prefix.size());
  }
  if (name == "hip" || name == "lower_body" || name == "upper_body") return Group::kBody;
  if (name == "head") return Group::kHead;
  if (name == "eye") return Group::kEyes;
  if (name == "upper_arm" || name == "lower_arm") return Group::kArms;
  if (name == "hand") return Group::kHands;
  if (name == "upper_leg" || name == "lower_leg") return Group::kLegs;
  if (name == "foot" || name == "toes" || name == "big_toe") return Group::kFeet;
  // Everything else of MIMo is a finger segment: v1 "fingers" or v2 ff/mf/rf/lf/th bodies.
  return Group::kFingers;
}

int joint_count(const Infant& infant) {
  int n = 0;
  for (const Body& b : infant.bodies) n += static_cast<int>(b.joints.size());
  return n;
}

std::vector<std::pair<const Body*, const Joint*>> joints_in_order(const Infant& infant) {
  std::vector<std::pair<const Body*, const Joint*>> out;
  for (const Body& b : infant.bodies) {
    for (const Joint& j : b.joints) out.emplace_back(&b, &j);
  }
  return out;
}

Infant make_mimo(MimoVersion version) {
  return version == MimoVersion::kV1 ? make_mimo_v1() : make_mimo_v2();
}

}  // namespace cradle::model

// MIMo v2: five-fingered hands (Adroit layout) and feet with a big toe and a toes body. Numbers are
// the reference model's (mimo_core.md §1.1, §1.5-1.6, §2.2). The left hand is the right one seen
// in a mirror across the sagittal plane: y offsets and the x/z parts of hinge axes flip sign.
#include <array>
#include <string>
#include <utility>
#include <vector>

#include "model/infant.h"
#include "model/infant_parts.h"

namespace cradle::model {
namespace {

// One finger segment: its capsule along +z, the flexion spring, and where the next segment starts.
struct Phalanx {
  double radius, half, z, mass;
  double stiffness;  // flexion joint stiffness
  double next = 0;   // z offset of the child segment (unused on the distal one)
};

// A knuckle -> middle -> distal chain: where it attaches and its three segments.
struct FingerChain {
  const char* key;  // "ff", "mf", "rf", "lf"
  const char* parent;
  Vec3 pos;
  std::array<Phalanx, 3> segments;
};

// Flexion joint of each segment: name, range and spring rest angle (degrees).
struct Flexion {
  const char* name;
  double lo, hi, springref;
};
constexpr std::array<Flexion, 3> kFlexion = {
    {{"knuckle", -20, 90, 45}, {"middle", -5, 100, 45}, {"distal", -5, 80, 30}}};

constexpr std::array<FingerChain, 4> kFingers = {{
    {"ff",
     "hand",
     {0.01177, 0, 0.02945},
     {{{.00549, .00992, .00992, .002692, .0008, .01985},
       {.0052, .00501, .00806, .001497, .0006, .0135},
       {.0050, .00464, .00669, .001291, .0006}}}},
    {"mf",
     "hand",
     {0, 0, 0.03152},
     {{{.00579, .011, .011, .003284, .0010, .022},
       {.0054, .00562, .00867, .001757, .0007, .0145},
       {.0052, .00538, .00742, .001563, .0006}}}},
    {"rf",
     "hand",
     {-0.01177, 0, 0.02945},
     {{{.00549, .00978, .00978, .002664, .0009, .01956},
       {.0052, .00489, .00793, .001476, .0007, .013},
       {.0050, .00479, .00684, .001316, .0006}}}},
    {"lf",
     "lfmetacarpal",
     {-0.00849, 0, 0.02273},
     {{{.00529, .00816, .00816, .002143, .0007, .0166},
       {.0050, .00455, .005, .001276, .0006, .0092},
       {.0049, .00391, .00596, .001113, .0006}}}},
}};

// Collision bitmasks that keep a forearm off its own metacarpal and thumb base.
struct HandMasks {
  int forearm_type, forearm_affinity, base_type, base_affinity;
};
HandMasks hand_masks(Side side) {
  return side == Side::kRight ? HandMasks{8, 7, 16, 7} : HandMasks{2, 25, 4, 25};
}

// Palm and finger geoms use the full friction cone with torsion and rolling (condim 6).
Geom hand_geom(Geom geom) {
  geom.condim = 6;
  return geom;
}

// An empty body placed in its parent (member-wise, so no field is left to an implicit default).
Body make_body(std::string name, std::string parent, Vec3 pos) {
  Body b;
  b.name = std::move(name);
  b.parent = std::move(parent);
  b.pos = pos;
  return b;
}

// A finger-segment body with its torque site at the origin.
Body segment(const std::string& p, const std::string& body, const std::string& parent, Vec3 pos,
             const std::string& site) {
  Body b = make_body(p + body, p + parent, pos);
  b.sites.push_back({.name = "torque_" + p + site, .radius = 0.002});
  return b;
}

// Palm body with the wrist joints; the wrist anchors sit near the forearm end.
void add_palm(Infant& infant, Side side) {
  const double s = side == Side::kRight ? 1 : -1;
  const std::string p = side_prefix(side);
  Body hand = make_body(p + "hand", p + "lower_arm", {0.007, -s * 0.009, 0.11032});
  hand.geoms = {
      hand_geom(box("", {.01712, .00584, .02532}, {0, 0, 0}, {0, 0, 0}, .01895, "skin")),
      hand_geom(box("", {.00588, .00584, .01292}, {-.023, 0, -.0124}, {0, 0, 0}, .003321, "skin")),
      hand_geom(cylinder("", {.00584, .01710}, {0, 0, .02532}, {0, 90, 0}, .003367, "skin")),
      hand_geom(cylinder("", {.00584, .02298}, {-.00588, 0, -.02532}, {0, 90, 0}, .004524, "skin")),
  };
  hand.joints = {
      hinge(p + "hand1", {0, 0, -s}, {-0.007, s * 0.007, -.01532}, -90, 90, -20, .22, .03, .007,
            0.001),
      hinge(p + "hand2", {-s, 0, 0}, {-0.007, -s * 0.005, -.02032}, -92, 86, 0, .33, .11, .007,
            0.001),
      hinge(p + "hand3", {0, 1, 0}, {-0.007, 0, -.02532}, -53, 48, 0, .38, .11, .007, 0.001),
  };
  hand.sites.push_back({.name = "torque_" + p + "wrist", .radius = 0.002});
  infant.bodies.push_back(hand);
}

// Knuckle, middle and distal bodies of one finger; the knuckle also abducts about y.
void add_finger(Infant& infant, Side side, const FingerChain& finger) {
  const double s = side == Side::kRight ? 1 : -1;
  const std::string p = side_prefix(side);
  const std::string key = finger.key;
  std::string parent = finger.parent;
  Vec3 pos = finger.pos;
  for (int i = 0; i < 3; ++i) {
    const Phalanx& ph = finger.segments[i];
    const Flexion& flex = kFlexion[i];
    const std::string joint = key + "_" + flex.name;
    Body b = segment(p, key + flex.name, parent, pos, joint);
    b.geoms.push_back(
        hand_geom(capsule("", {ph.radius, ph.half}, {0, 0, ph.z}, {0, 0, 0}, ph.mass, "skin")));
    if (i == 0) {
      b.joints.push_back(
          hinge(p + key + "_side", {0, 1, 0}, {0, 0, 0}, -25, 25, 0, .003, .001, 0, .0001));
    }
    b.joints.push_back(hinge(p + joint, {s, 0, 0}, {0, 0, 0}, flex.lo, flex.hi, flex.springref,
                             ph.stiffness, .0005, 0, .0001));
    infant.bodies.push_back(b);
    parent = key + flex.name;
    pos = {0, 0, ph.next};
  }
}

// Little-finger metacarpal: folds the ulnar palm edge about an oblique axis.
void add_metacarpal(Infant& infant, Side side) {
  const double s = side == Side::kRight ? 1 : -1;
  const std::string p = side_prefix(side);
  const HandMasks masks = hand_masks(side);
  Body meta = segment(p, "lfmetacarpal", "hand", {-0.01498, 0, 0.0031}, "lf_meta");
  meta.geoms = {
      hand_geom(
          box("", {.00508, .00584, .01292}, {-.00883, 0, .00517}, {0, 0, 0}, .002879, "skin")),
      hand_geom(cylinder("", {.00584, .005}, {-.00883, 0, .01809}, {0, 90, 0}, .0009879, "skin")),
  };
  for (Geom& g : meta.geoms) {
    g.contype = masks.base_type;
    g.conaffinity = masks.base_affinity;
  }
  // Only the x part of this axis flips on the left (the reference's left axis is -.571 0 .821).
  meta.joints.push_back(
      hinge(p + "lf_meta", {s * .571, 0, .821}, {0, 0, 0}, 0, 40, 0, .01, .001, 0, .0001));
  infant.bodies.push_back(meta);
}

// Thumb: base (swivel, adduction) -> hub (pivot, middle flexion) -> distal.
void add_thumb(Infant& infant, Side side) {
  const double s = side == Side::kRight ? 1 : -1;
  const std::string p = side_prefix(side);
  const HandMasks masks = hand_masks(side);
  Body base = segment(p, "thbase", "hand", {0.0123, -s * 0.00423, -0.01602}, "th_base");
  base.euler = {0, 80, s * 30};
  Geom base_geom =
      hand_geom(capsule("", {.00736, .01027}, {0, 0, .01027}, {0, 0, 0}, .005463, "skin"));
  base_geom.contype = masks.base_type;
  base_geom.conaffinity = masks.base_affinity;
  base.geoms.push_back(base_geom);
  base.joints = {
      hinge(p + "th_swivel", {3 * s, -5, -s}, {0, 0, 0}, -10, 110, 40, .003, .001, 0, .0001),
      hinge(p + "th_adduction", {s, 2, 0}, {0, 0, 0}, -60, 0, -35, .004, .001, 0, .0001),
  };
  infant.bodies.push_back(base);

  Body hub = segment(p, "thhub", "thbase", {0, 0, 0.02125}, "th_hub");
  hub.geoms.push_back(
      hand_geom(capsule("", {.00638, .00697}, {0, 0, .0085}, {0, 0, 0}, .003021, "skin")));
  hub.joints = {
      hinge(p + "th_pivot", {s, 0, 0}, {0, 0, 0}, -10, 10, 0, .002, .001, 0, .0001),
      hinge(p + "th_middle", {0, -1, 0}, {0, 0, 0}, 0, 90, 30, .004, .001, 0, .0001),
  };
  infant.bodies.push_back(hub);

  Body distal = segment(p, "thdistal", "thhub", {0, 0, 0.015}, "th_distal");
  distal.geoms.push_back(
      hand_geom(capsule("", {.00618, .00587}, {0, 0, .00996}, {0, 0, 0}, .002509, "skin")));
  distal.joints.push_back(
      hinge(p + "th_distal", {0, -1, 0}, {0, 0, 0}, 0, 90, 20, .004, .001, 0, .0001));
  infant.bodies.push_back(distal);
}

// Whole hand in reference body order: palm, ff, mf, rf, little finger, thumb.
void add_hand(Infant& infant, Side side) {
  add_palm(infant, side);
  for (int i = 0; i < 3; ++i) add_finger(infant, side, kFingers[i]);
  add_metacarpal(infant, side);
  add_finger(infant, side, kFingers[3]);
  add_thumb(infant, side);
}

// Foot with a big-toe and a toes body. The reference lists big_toe first on the right foot and
// toes first on the left.
void add_foot(Infant& infant, Side side) {
  const double s = side == Side::kRight ? 1 : -1;
  const std::string p = side_prefix(side);
  add_foot_body(infant, side,
                {
                    cylinder("", {.0249, .0101}, {-0.007, 0, 0}, {0, 0, 0}, .03225, "sock"),
                    box("", {.030, .025, .01}, {0.023, 0, 0}, {0, 0, 0}, .04923, "sock"),
                    cylinder("", {.0101, .0251}, {.053, 0, 0}, {90, 0, 0}, .01312, "sock"),
                });

  // A toe body: a box and a rounded tip across the foot; the big toe is medial (+y on the right).
  auto toe = [&](const std::string& name, double y, double box_half_width, double box_mass,
                 double tip_half_length, double tip_mass) {
    Body b = make_body(p + name, p + "foot", {.053, y, 0});
    b.geoms = {
        box("", {.0095, box_half_width, .0099}, {.0095, 0, 0}, {0, 0, 0}, box_mass, "sock"),
        cylinder("", {.01, tip_half_length}, {.019, 0, 0}, {90, 0, 0}, tip_mass, "sock"),
    };
    for (Geom& g : b.geoms) g.friction = kSoleGrip;
    b.joints.push_back(hinge(p + name, {0, -1, 0}, {0, 0, 0}, -60, 80, 0, .053, .02, .002, .0001));
    b.sites.push_back({.name = "torque_" + p + name});
    return b;
  };
  Body big_toe = toe("big_toe", s * .0175, .007, .004425, .0075, .003934);
  Body toes = toe("toes", -s * .0075, .016, .01006, .0165, .008612);
  if (side == Side::kRight) {
    infant.bodies.push_back(big_toe);
    infant.bodies.push_back(toes);
  } else {
    infant.bodies.push_back(toes);
    infant.bodies.push_back(big_toe);
  }
}

// One row of the finger actuator table: joint suffix, actuator suffix, gear, force range, user.
struct FingerMotor {
  const char* actuator;
  const char* joint;
  double gear, lo, hi;
  std::array<double, 3> user;
};
constexpr std::array<FingerMotor, 22> kFingerMotors = {{
    {"ff_side", "ff_side", .05, -1, 1, {6.217, .1556, .1556}},
    {"ff_knuckle", "ff_knuckle", .0619, -.345, 1, {4.368, .1422, .4378}},
    {"ff_middle", "ff_middle", .02063, -.345, 1, {3.493, .04684, .1339}},
    {"ff_distal", "ff_distal", .01548, -.345, 1, {2.539, .03054, .07747}},
    {"mf_side", "mf_side", .05, -1, 1, {5.375, .1556, .1556}},
    {"mf_knuckle", "mf_knuckle", .117, -.345, 1, {4.325, .2687, .8275}},
    {"mf_middle", "mf_middle", .039, -.345, 1, {3.375, .08855, .2532}},
    {"mf_distal", "mf_distal", .02925, -.345, 1, {2.577, .05771, .1464}},
    {"rf_side", "rf_side", .05, -1, 1, {4.984, .1556, .1556}},
    {"rf_knuckle", "rf_knuckle", .078, -.345, 1, {2.817, .1791, .5517}},
    {"rf_middle", "rf_middle", .026, -.345, 1, {3.007, .05903, .1688}},
    {"rf_distal", "rf_distal", .0195, -.345, 1, {2.313, .03847, .09759}},
    {"lf_side", "lf_side", .05, -1, 1, {5.282, .1556, .1556}},
    {"lf_meta", "lf_meta", .064, -.345, 1, {6.855, .07962, .1508}},
    {"lf_knuckle", "lf_knuckle", .0196, -.345, 1, {2.337, .04502, .1386}},
    {"lf_middle", "lf_middle", .00653, -.345, 1, {2.566, .01483, .04239}},
    {"lf_distal", "lf_distal", .00490, -.345, 1, {2.001, .009666, .02452}},
    {"thumb_side", "th_swivel", .373, -.345, 1, {3.491, 1.117, 2.604}},
    {"thumb_add", "th_adduction", .134, -1, 1, {5.646, .4969, .5024}},
    {"thumb_pivot", "th_pivot", .1, -1, 1, {9.055, .1868, .1868}},
    {"thumb_middle", "th_middle", .126, -.345, 1, {3.877, .2433, .7065}},
    {"thumb_distal", "th_distal", .0945, -.345, 1, {3.392, .2053, .4959}},
}};

// A v2 toe actuator; only the muscle velocity limit differs between the two rows of a foot.
Actuator toe_motor(const std::string& name, double vmax) {
  return {.name = name,
          .joint = name,
          .group = Group::kFeet,
          .gear = .165,
          .force_lo = -1,
          .force_hi = .3,
          .user = {vmax, 1.473, .4220}};
}

// Torque-sensor suffixes of one hand after the wrist, in sensordata order.
constexpr std::array<const char*, 16> kFingerSensors = {
    "ff_knuckle", "ff_middle", "ff_distal", "mf_knuckle", "mf_middle",  "mf_distal",
    "rf_knuckle", "rf_middle", "rf_distal", "lf_meta",    "lf_knuckle", "lf_middle",
    "lf_distal",  "th_base",   "th_hub",    "th_distal"};

}  // namespace

Infant make_mimo_v2() {
  Infant infant;
  infant.version = MimoVersion::kV2;

  // Tree in document order: trunk, head, eyes, right arm, left arm, right leg, left leg.
  add_trunk_and_head(infant, TrunkMasses{.lb = 1.1684,
                                         .cb = 1.3359,
                                         .ub1 = 1.0976,
                                         .ub2 = .9531,
                                         .ub3 = .7279,
                                         .head = 1.7901,
                                         .eye = .006329});
  for (Side side : {Side::kRight, Side::kLeft}) {
    add_arm(infant, side, .2708, .1869);
    // The forearm gets its own collision bits so it skips its hand's metacarpal and thumb base.
    const HandMasks masks = hand_masks(side);
    Geom& forearm = infant.bodies.back().geoms.front();
    forearm.contype = masks.forearm_type;
    forearm.conaffinity = masks.forearm_affinity;
    add_hand(infant, side);
  }
  for (Side side : {Side::kRight, Side::kLeft}) {
    add_leg(infant, side, LegMasses{.thigh = .8067, .shank1 = .3370, .shank2 = .1170});
    add_foot(infant, side);
  }

  // Actuators: the finger table per hand; upstream v2 toe rows (BabyBench's kit swaps in v1's
  // numbers), the left foot listing toes first.
  add_actuators(
      infant,
      [&](Side side) {
        const std::string p = side_prefix(side);
        for (const FingerMotor& m : kFingerMotors) {
          infant.actuators.push_back({.name = p + m.actuator,
                                      .joint = p + m.joint,
                                      .group = Group::kFingers,
                                      .gear = m.gear,
                                      .force_lo = m.lo,
                                      .force_hi = m.hi,
                                      .user = m.user});
        }
      },
      [&](Side side) {
        const bool right = side == Side::kRight;
        infant.actuators.push_back(toe_motor(right ? "right_big_toe" : "left_toes", 1.774));
        infant.actuators.push_back(toe_motor(right ? "right_toes" : "left_big_toe", 1.805));
      });

  // Torque sensors: the arms' fingers after the wrist, the big toe after the toes.
  std::vector<std::string> arm_sensors = {"shoulder", "elbow", "wrist"};
  arm_sensors.insert(arm_sensors.end(), kFingerSensors.begin(), kFingerSensors.end());
  add_torque_sensors(infant, arm_sensors, {"hip", "knee", "ankle", "toes", "big_toe"});

  add_tendons_and_contacts(infant);
  return infant;
}

}  // namespace cradle::model

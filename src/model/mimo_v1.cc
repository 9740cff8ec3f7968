// MIMo v1: mitten hands (one palm body and one "fingers" body per hand) and one toes body per
// foot. Numbers are the reference model's (mimo_core.md §1.2-1.3, §1.6, §2.1).
#include <string>

#include "model/infant.h"
#include "model/infant_parts.h"

namespace cradle::model {
namespace {

// Palm body and one mitten "fingers" body.
void add_mitten(Infant& infant, Side side) {
  const double s = side == Side::kRight ? 1 : -1;
  const std::string p = side_prefix(side);
  Body hand{.name = p + "hand", .parent = p + "lower_arm", .pos = {0, -.007, .087}};
  hand.geoms = {
      box("", {.0281, .01, .0208}, {.005, 0, .0208}, {0, 0, 0}, .04315, "skin"),
      cylinder("", {.0102, .0278}, {.005, 0, .0416}, {0, 90, 0}, .01602, "skin"),
  };
  hand.joints = {
      hinge(p + "hand1", {0, 0, -s}, {0, .007, 0}, -90, 90, -20, .22, .03, .007, 0.001),
      hinge(p + "hand2", {-s, 0, 0}, {0, 0, 0}, -92, 86, 0, .33, .11, .007, 0.001),
      hinge(p + "hand3", {0, 1, 0}, {0, 0, 0}, -53, 48, 0, .38, .11, .007, 0.001),
  };
  hand.sites.push_back({.name = "torque_" + p + "wrist"});
  infant.bodies.push_back(hand);

  // The mitten grips: five times the skin's sliding friction.
  Body fingers{.name = p + "fingers", .parent = p + "hand", .pos = {0, 0, .0416}};
  fingers.geoms = {
      box("", {.0228, .01, .0207}, {0, 0, .0207}, {0, 0, 0}, .03494, "skin"),
      cylinder("", {.0102, .023}, {0, 0, .0414}, {0, 90, 0}, .01323, "skin"),
  };
  for (Geom& g : fingers.geoms) g.friction = Vec3{5, 0.02, 0.01};
  fingers.joints.push_back(
      hinge(p + "fingers", {-s, 0, 0}, {0, 0, 0}, -160, 8, -40, .017, .018, .0023, 0.0001));
  fingers.sites.push_back({.name = "torque_" + p + "fingers"});
  infant.bodies.push_back(fingers);
}

// Foot body and one toes body.
void add_foot(Infant& infant, Side side) {
  const std::string p = side_prefix(side);
  add_foot_body(infant, side,
                {
                    cylinder("", {.0249, .0099}, {-0.016, 0, 0}, {0, 0, 0}, .03219, "sock"),
                    box("", {.035, .025, .01}, {0.019, 0, 0}, {0, 0, 0}, .05850, "sock"),
                    cylinder("", {.0099, .0248}, {.054, 0, 0}, {90, 0, 0}, .01268, "sock"),
                });

  Body toes{.name = p + "toes", .parent = p + "foot", .pos = {.054, 0, 0}};
  toes.geoms = {
      box("", {.007, .0249, .0099}, {.007, 0, 0}, {0, 0, 0}, .01084, "sock"),
      cylinder("", {.01, .025}, {.014, 0, 0}, {90, 0, 0}, .01226, "sock"),
  };
  for (Geom& g : toes.geoms) g.friction = kSoleGrip;
  toes.joints.push_back(
      hinge(p + "toes", {0, -1, 0}, {0, 0, 0}, -60, 80, 0, .106, .04, .005, .0005));
  toes.sites.push_back({.name = "torque_" + p + "toes"});
  infant.bodies.push_back(toes);
}

}  // namespace

Infant make_mimo_v1() {
  Infant infant;
  infant.version = MimoVersion::kV1;

  // Tree in document order: trunk, head, eyes, right arm, left arm, right leg, left leg.
  add_trunk_and_head(infant, TrunkMasses{});
  for (Side side : {Side::kRight, Side::kLeft}) {
    add_arm(infant, side, .2684, .1853);
    add_mitten(infant, side);
  }
  for (Side side : {Side::kRight, Side::kLeft}) {
    add_leg(infant, side, LegMasses{});
    add_foot(infant, side);
  }

  // Actuators: one mitten motor per hand, one toes motor per foot.
  add_actuators(
      infant,
      [&](Side side) {
        const std::string p = side_prefix(side);
        infant.actuators.push_back({.name = p + "fingers",
                                    .joint = p + "fingers",
                                    .group = Group::kFingers,
                                    .gear = .69,
                                    .force_lo = -1,
                                    .force_hi = .33,
                                    .user = {3.019, 6.854, 2.551}});
      },
      [&](Side side) {
        const std::string p = side_prefix(side);
        infant.actuators.push_back({.name = p + "toes",
                                    .joint = p + "toes",
                                    .group = Group::kFeet,
                                    .gear = .33,
                                    .force_lo = -1,
                                    .force_hi = .3,
                                    .user = {1.290, 2.947, .8440}});
      });

  add_torque_sensors(infant, {"shoulder", "elbow", "wrist", "fingers"},
                     {"hip", "knee", "ankle", "toes"});

  add_tendons_and_contacts(infant);
  return infant;
}

}  // namespace cradle::model

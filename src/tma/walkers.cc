// Walkers (and the amphibious bipedal): bipedals, quadruped, spider, millipede, chimpanzee.
// Geometry from tma_bodies.md §1-2 and the reference's body files; positions are world units.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "tma/agent.h"

namespace cradle::tma {
namespace {

using build::Fixture;
constexpr double kPi = std::numbers::pi;
constexpr Rgb kHull1{0.5f, 0.4f, 0.9f}, kHull2{0.3f, 0.3f, 0.5f};

Rgb leg1(double i) {
  return Rgb{static_cast<float>(0.6 - i / 10), static_cast<float>(0.3 - i / 10),
             static_cast<float>(0.5 - i / 10)};
}
Rgb leg2(double i) {
  return Rgb{static_cast<float>(0.4 - i / 10), static_cast<float>(0.2 - i / 10),
             static_cast<float>(0.3 - i / 10)};
}

// The reference object (hull or main body): contact-checked, critical when asked, pushed at reset.
b2Body* hull(Agent& agent, b2World& world, double x0, double y0, const b2PolygonShape& shape,
             double density, bool critical, Rgb c1, Rgb c2) {
  b2Body* hull = build::part(agent, world, at(x0, y0), 0, shape,
                             Fixture{.density = density, .friction = 0.1}, true, critical, c1, c2);
  agent.head = hull;
  agent.pushed.push_back(hull);
  return hull;
}

// A walker leg's sizes (world units), how far below the hull its hip sits, and its material.
struct Leg {
  double w, h, down;
  Fixture fd{};
};

// Colours of a leg's upper and lower parts.
struct LegColors {
  Rgb upper1, upper2, lower1, lower2;
};
LegColors leg_colors(double i) { return {leg1(i), leg2(i), leg1(i), leg2(i)}; }

// A straight two-part leg hanging from `parent` at (x, y0 - down), world anchors: the hip motor,
// then the knee motor, which observes the lower part's contact.
void straight_leg(Agent& agent, b2World& world, b2Body* parent, double x, double y0, const Leg& leg,
                  const LegColors& c) {
  b2Body* upper =
      build::part(agent, world, at(x, y0 - leg.h / 2 - leg.down), 0,
                  build::box(leg.w / 2, leg.h / 2), leg.fd, false, false, c.upper1, c.upper2);
  build::motor(agent, build::joint(world, parent, upper, at(x, y0 - leg.down), -0.8, 1.1, true), 4);
  b2Body* lower =
      build::part(agent, world, at(x, y0 - leg.h * 1.5 - leg.down), 0,
                  build::box(0.8 * leg.w / 2, leg.h / 2), leg.fd, true, false, c.lower1, c.lower2);
  build::motor(agent,
               build::joint(world, upper, lower, at(x, y0 - leg.down - leg.h), -1.6, -0.1, true), 6,
               lower, 1.0);
}

// The old morphologies' leg: spawned at x tilted by i * 0.05 rad, its joints from local anchors
// (the hip at (x_anchor, down) on the hull, used raw). The hip starts violated by 0.53 (inherited
// from gym's BipedalWalker) and the solver closes it in the first step.
void tilted_leg(Agent& agent, b2World& world, b2Body* hull, double x, double y0, double x_anchor,
                double i, const Leg& leg) {
  b2Body* upper =
      build::part(agent, world, at(x, y0 - leg.h / 2 - leg.down), i * 0.05,
                  build::box(leg.w / 2, leg.h / 2), leg.fd, false, false, leg1(i), leg2(i));
  build::motor(
      agent,
      build::joint_local(world, hull, upper, at(x_anchor, leg.down), at(0, leg.h / 2), -0.8, 1.1),
      4);
  b2Body* lower =
      build::part(agent, world, at(x, y0 - leg.h * 1.5 - leg.down), i * 0.05,
                  build::box(0.8 * leg.w / 2, leg.h / 2), leg.fd, true, false, leg1(i), leg2(i));
  build::motor(
      agent,
      build::joint_local(world, upper, lower, at(0, -leg.h / 2), at(0, leg.h / 2), -1.6, -0.1), 6,
      lower, 1.0);
}

// Every bipedal's hull (pixels of the reference's body file) with their torque.
b2Body* bipedal_hull(Agent& agent, b2World& world, double x0, double y0, double density,
                     bool critical, Rgb c1, Rgb c2) {
  agent.torque = 80;
  agent.torque_penalty = 3.5e-4;
  return hull(agent, world, x0, y0,
              build::pixel_polygon({{-30, 9}, {6, 9}, {34, 1}, {34, -8}, {-30, -8}}), density,
              critical, c1, c2);
}

// The hull both big quadrupeds share (they differ only in how their legs hang from it).
b2Body* quadru_hull(Agent& agent, b2World& world, double x0, double y0, bool critical) {
  agent.torque = 300;
  agent.torque_penalty = 3.5e-4 / 2;
  return hull(agent, world, x0, y0,
              build::pixel_polygon({{-46, 13}, {6, 13}, {50, 5}, {50, -12}, {-46, -12}}), 5.0,
              critical, kHull1, kHull2);
}

// The 20 x 20 pixel square of the spider, the millipede's segments and the wheel.
b2PolygonShape square() {
  return build::pixel_polygon({{-10, 10}, {10, 10}, {10, -10}, {-10, -10}});
}

// Straight-legged bipedals (classic, small, amphibious): world anchors, legs not tilted.
struct BipedalSpec {
  Leg leg;
  double hull_density;
  bool critical_hull;
  Rgb hull1 = kHull1, hull2 = kHull2;
  bool amphibian_colors = false;
};

void straight_bipedal(Agent& agent, b2World& world, double x0, double y0, const BipedalSpec& s) {
  b2Body* hull =
      bipedal_hull(agent, world, x0, y0, s.hull_density, s.critical_hull, s.hull1, s.hull2);
  for (double i : {-1.0, 1.0}) {
    const LegColors c = s.amphibian_colors ? LegColors{s.hull1, s.hull2, Rgb{1.0f, 0.25f, 0.04f},
                                                       Rgb{0.86f, 0.29f, 0.12f}}
                                           : leg_colors(i);
    straight_leg(agent, world, hull, x0, y0, s.leg, c);
  }
}

}  // namespace

void build_old_classic_bipedal(Agent& agent, b2World& world, double x0, double y0,
                               bool critical_hull) {
  b2Body* hull = bipedal_hull(agent, world, x0, y0, 5.0, critical_hull, kHull1, kHull2);
  const Leg leg{.w = 8 / kScale, .h = 34 / kScale, .down = -8 / kScale};
  for (double i : {-1.0, 1.0}) tilted_leg(agent, world, hull, x0, y0, 0, i, leg);
}

void build_classic_bipedal(Agent& agent, b2World& world, double x0, double y0, bool critical_hull) {
  straight_bipedal(agent, world, x0, y0,
                   BipedalSpec{.leg = {.w = 8 / kScale, .h = 34 / kScale, .down = 3 / kScale},
                               .hull_density = 5.0,
                               .critical_hull = critical_hull});
}

void build_small_bipedal(Agent& agent, b2World& world, double x0, double y0, bool critical_hull) {
  straight_bipedal(agent, world, x0, y0,
                   BipedalSpec{.leg = {.w = 8 / kScale, .h = 17 / kScale, .down = 3 / kScale},
                               .hull_density = 5.0,
                               .critical_hull = critical_hull});
}

void build_amphibious_bipedal(Agent& agent, b2World& world, double x0, double y0) {
  straight_bipedal(agent, world, x0, y0,
                   BipedalSpec{.leg = {.w = 8 / kScale,
                                       .h = 34 / kScale,
                                       .down = 3 / kScale,
                                       .fd = {.density = 0.25 * kWaterDensity}},
                               .hull_density = 1.25 * kWaterDensity,
                               .critical_hull = false,
                               .hull1 = {0.44f, 0.81f, 0.14f},
                               .hull2 = {0.36f, 0.66f, 0.11f},
                               .amphibian_colors = true});
}

void build_old_big_quadru(Agent& agent, b2World& world, double x0, double y0, bool critical_hull) {
  b2Body* hull = quadru_hull(agent, world, x0, y0, critical_hull);
  const Leg leg{.w = 10 / kScale, .h = 51 / kScale, .down = -8 / kScale};
  const double half_bottom = 96 / 2 / kScale;
  // The local anchor x is used raw while the spawn x is np.interp'ed (and clamped) onto the hull.
  for (double x_anchor : {-1.2, 0.85}) {
    const double ax = x0 + std::clamp(x_anchor, -1.0, 1.0) * half_bottom;
    for (double i : {-1.0, 1.0}) tilted_leg(agent, world, hull, ax, y0, x_anchor, i, leg);
  }
}

void build_spider(Agent& agent, b2World& world, double x0, double y0, bool critical_hull) {
  const int pairs = agent.options.nb_pairs_of_legs;
  agent.torque = 100;
  agent.torque_penalty = 3.5e-4 / pairs;
  const double h = 10 / kScale;  // half leg length
  b2Body* main = hull(agent, world, x0, y0, square(), 5.0, critical_hull, kHull1, kHull2);
  const b2PolygonShape upper_shape = build::box(3 / kScale, h);
  const b2PolygonShape lower_shape = build::box(2.4 / kScale, h);
  // Sides +1, -1 per pair: every pair is the same two legs, overlapping (own parts never collide).
  for (int leg = 0; leg < 2 * pairs; ++leg) {
    const double s = leg % 2 == 0 ? 1.0 : -1.0;
    const double a1 = 0.25 * kPi * s, a2 = 0.7 * kPi * s, a3 = 0.9 * kPi * s;
    const double ux = x0 - s / 3 - std::sin(a1) * h, uy = y0 + std::cos(a1) * h - 4 / kScale;
    b2Body* upper = build::part(agent, world, at(ux, uy), a1, upper_shape, Fixture{}, false, false,
                                leg1(s), leg2(s));
    build::motor(agent,
                 build::joint(world, main, upper, at(x0 - s / 3, y0 - 4 / kScale), -0.1 * kPi,
                              0.1 * kPi, true),
                 4);
    const double kx = ux - std::sin(a1) * h, ky = uy + std::cos(a1) * h;
    const double mx = kx - std::sin(a2) * h, my = ky + std::cos(a2) * h;
    b2Body* middle = build::part(agent, world, at(mx, my), a2, upper_shape, Fixture{}, false, false,
                                 leg1(s), leg2(s));
    build::motor(agent,
                 build::joint(world, upper, middle, at(kx, ky), -0.15 * kPi, 0.15 * kPi, true), 4);
    const double ax = mx - std::sin(a2) * h, ay = my + std::cos(a2) * h;
    const double lx = ax - std::sin(a3) * h, ly = ay + std::cos(a3) * h;
    b2Body* lower = build::part(agent, world, at(lx, ly), a3, lower_shape, Fixture{}, true, false,
                                leg1(s), leg2(s));
    build::motor(agent, build::joint(world, middle, lower, at(ax, ay), -0.2 * kPi, 0.2 * kPi, true),
                 6, lower, 0);
  }
}

void build_millipede(Agent& agent, b2World& world, double x0, double y0) {
  agent.torque = 200;
  // One pair of legs per segment; the torque penalty is shared out over the pairs.
  const int bodies = agent.options.nb_of_bodies;
  agent.torque_penalty = 3.5e-4 / bodies;
  const Leg leg{.w = 4 / kScale, .h = 10 / kScale, .down = 3 / kScale};
  const double seg = 20 / kScale;
  const b2PolygonShape main_shape = square();
  const double left = x0 - seg * bodies / 2;
  b2Body* previous = nullptr;
  for (int j = 0; j < bodies; ++j) {
    const double bx = left + j * seg;
    // Segments are never critical (the reference sets an unused attribute); each is the head in
    // turn, so the rightmost one stays it.
    b2Body* main = hull(agent, world, bx, y0, main_shape, 5.0, false, kHull1, kHull2);
    for (double i : {-1.0, 1.0}) straight_leg(agent, world, main, bx, y0, leg, leg_colors(i));
    if (previous) {
      build::joint(world, previous, main, at(bx - seg / 2, y0), -0.05 * kPi, 0.05 * kPi, false);
    }
    previous = main;
  }
}

void build_profile_chimpanzee(Agent& agent, b2World& world, double x0, double y0) {
  const build::Chimpanzee c = build::chimpanzee(agent, world, x0, y0, true, false);
  const double arm_up = c.kArmUp, limb_h = c.kLimbH, hand_h = c.kHandH;
  // Two identical arms hanging from the shoulder, each: upper arm, forearm, then a three-part hand.
  const double hand_limits[3][2] = {{-0.4, 0.35}, {-0.5, 0}, {-0.8, 0}};
  for (int k = 0; k < 2; ++k) {
    b2Body* upper = build::part(agent, world, at(x0, y0 - limb_h / 2 + arm_up), 0, c.upper,
                                c.limb_fd, false, false, leg1(-1), leg2(-1));
    build::motor(
        agent,
        build::joint(world, c.torso, upper, at(x0, y0 + arm_up), -0.5 * kPi, 0.8 * kPi, true), 4);
    b2Body* lower = build::part(agent, world, at(x0, y0 - limb_h * 1.5 + arm_up), 0, c.lower,
                                c.limb_fd, false, false, leg1(-1), leg2(-1));
    build::motor(
        agent, build::joint(world, upper, lower, at(x0, y0 - limb_h + arm_up), 0, 0.75 * kPi, true),
        4);
    b2Body* previous = lower;
    const double y_hand = y0 - limb_h * 2 + arm_up;
    for (int u = 0; u < 3; ++u) {
      b2Body* hand = build::part(agent, world, at(x0, y_hand - hand_h / 2 - hand_h * u), 0, c.hand,
                                 c.limb_fd, true, false, leg1(-1), leg2(-1));
      build::motor(agent,
                   build::joint(world, previous, hand, at(x0, y_hand - hand_h * u),
                                hand_limits[u][0] * kPi, hand_limits[u][1] * kPi, true),
                   8, hand, 0);
      previous = hand;
    }
  }
}

void build_big_quadru(Agent& agent, b2World& world, double x0, double y0, bool critical_hull) {
  b2Body* hull = quadru_hull(agent, world, x0, y0, critical_hull);
  const Leg leg{.w = 10 / kScale, .h = 51 / kScale, .down = 3 / kScale};
  const double half_bottom = 96 / 2 / kScale;
  // Straight legs hanging from two points of the hull, world anchors.
  for (double x_anchor : {-0.7, 0.5}) {
    const double ax = x0 + x_anchor * half_bottom;
    for (double i : {-1.0, 1.0}) straight_leg(agent, world, hull, ax, y0, leg, leg_colors(i));
  }
}

void build_wheel(Agent& agent, b2World& world, double x0, double y0, bool critical_hull) {
  agent.torque = 500;
  agent.torque_penalty = 3.5e-4 / 2;
  agent.remove_head_angle = true;
  const double leg_w = 4 / kScale, leg_h = 10 / kScale, half = 10 / kScale;
  const Rgb body1{0.5f, 0.2f, 0.4f}, body2{0.3f, 0.1f, 0.2f};
  const Rgb limb1{0.7f, 0.4f, 0.6f}, limb2{0.5f, 0.3f, 0.4f};
  b2Body* main = hull(agent, world, x0, y0, square(), 5.0, critical_hull, body1, body2);
  const b2PolygonShape leg_shape = build::box(leg_w / 2, leg_h / 2);
  const b2PolygonShape lower_shape = build::box(0.8 * leg_w / 2, leg_h / 2);
  // Four two-part legs in a cross: down, up, left, right.
  const double dirs[4][3] = {{0, -1, 0}, {0, 1, 0}, {-1, 0, kPi / 2}, {1, 0, kPi / 2}};
  for (const auto& d : dirs) {
    const double lx = x0 + d[0] * (leg_h / 2 + half), ly = y0 + d[1] * (leg_h / 2 + half);
    b2Body* leg = build::part(agent, world, at(lx, ly), d[2], leg_shape, Fixture{}, false, false,
                              limb1, limb2);
    build::motor(
        agent,
        build::joint(world, main, leg, at(x0 + d[0] * half, y0 + d[1] * half), -0.8, 1.1, true), 4);
    b2Body* lower = build::part(agent, world, at(lx + d[0] * leg_h, ly + d[1] * leg_h), d[2],
                                lower_shape, Fixture{}, true, false, limb1, limb2);
    build::motor(agent,
                 build::joint(world, leg, lower, at(lx + d[0] * leg_h / 2, ly + d[1] * leg_h / 2),
                              -1.6, -0.1, true),
                 6, lower, 1.0);
  }
}

}  // namespace cradle::tma

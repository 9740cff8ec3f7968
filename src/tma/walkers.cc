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
b2Vec2 at(double x, double y) { return b2Vec2(static_cast<float>(x), static_cast<float>(y)); }

b2PolygonShape bipedal_hull() {
  return build::pixel_polygon({{-30, 9}, {6, 9}, {34, 1}, {34, -8}, {-30, -8}});
}

// Straight-legged bipedals (classic, small, amphibious): world anchors, legs not tilted.
struct BipedalSpec {
  double leg_down, leg_w, leg_h;
  double hull_density, leg_density;
  bool critical_hull;
  Rgb hull1 = kHull1, hull2 = kHull2;
  bool amphibian_colors = false;
};

void straight_bipedal(Agent& agent, b2World& world, double x0, double y0, const BipedalSpec& s) {
  agent.torque = 80;
  agent.torque_penalty = 3.5e-4;
  const b2PolygonShape hull_shape = bipedal_hull();
  b2Body* hull = build::part(agent, world, at(x0, y0), 0, hull_shape,
                             Fixture{.density = s.hull_density, .friction = 0.1}, true,
                             s.critical_hull, s.hull1, s.hull2);
  agent.head = hull;
  agent.pushed.push_back(hull);
  const b2PolygonShape leg_shape = build::box(s.leg_w / 2, s.leg_h / 2);
  const b2PolygonShape lower_shape = build::box(0.8 * s.leg_w / 2, s.leg_h / 2);
  const Fixture leg_fd{.density = s.leg_density};
  for (double i : {-1.0, 1.0}) {
    const Rgb c1 = s.amphibian_colors ? s.hull1 : leg1(i),
              c2 = s.amphibian_colors ? s.hull2 : leg2(i);
    b2Body* leg = build::part(agent, world, at(x0, y0 - s.leg_h / 2 - s.leg_down), 0, leg_shape,
                              leg_fd, false, false, c1, c2);
    build::motor(agent, build::joint(world, hull, leg, at(x0, y0 - s.leg_down), -0.8, 1.1, true),
                 4);
    const Rgb l1 = s.amphibian_colors ? Rgb{1.0f, 0.25f, 0.04f} : c1;
    const Rgb l2 = s.amphibian_colors ? Rgb{0.86f, 0.29f, 0.12f} : c2;
    b2Body* lower = build::part(agent, world, at(x0, y0 - s.leg_h * 1.5 - s.leg_down), 0,
                                lower_shape, leg_fd, true, false, l1, l2);
    build::motor(
        agent, build::joint(world, leg, lower, at(x0, y0 - s.leg_down - s.leg_h), -1.6, -0.1, true),
        6, lower, 1.0);
  }
}

}  // namespace

void build_old_classic_bipedal(Agent& agent, b2World& world, double x0, double y0,
                               bool critical_hull) {
  agent.torque = 80;
  agent.torque_penalty = 3.5e-4;
  const double leg_down = -8 / kScale, leg_w = 8 / kScale, leg_h = 34 / kScale;
  const b2PolygonShape hull_shape = bipedal_hull();
  b2Body* hull =
      build::part(agent, world, at(x0, y0), 0, hull_shape, Fixture{.density = 5.0, .friction = 0.1},
                  true, critical_hull, kHull1, kHull2);
  agent.head = hull;
  agent.pushed.push_back(hull);
  const b2PolygonShape leg_shape = build::box(leg_w / 2, leg_h / 2);
  const b2PolygonShape lower_shape = build::box(0.8 * leg_w / 2, leg_h / 2);
  // Legs spawn tilted by +-0.05 rad with explicit local anchors: the hip starts violated by 0.53
  // (inherited from gym's BipedalWalker) and the solver closes it in the first step.
  for (double i : {-1.0, 1.0}) {
    b2Body* leg = build::part(agent, world, at(x0, y0 - leg_h / 2 - leg_down), i * 0.05, leg_shape,
                              Fixture{}, false, false, leg1(i), leg2(i));
    build::motor(agent,
                 build::joint_local(world, hull, leg, at(0, leg_down), at(0, leg_h / 2), -0.8, 1.1),
                 4);
    b2Body* lower = build::part(agent, world, at(x0, y0 - leg_h * 1.5 - leg_down), i * 0.05,
                                lower_shape, Fixture{}, true, false, leg1(i), leg2(i));
    build::motor(
        agent,
        build::joint_local(world, leg, lower, at(0, -leg_h / 2), at(0, leg_h / 2), -1.6, -0.1), 6,
        lower, 1.0);
  }
}

void build_classic_bipedal(Agent& agent, b2World& world, double x0, double y0, bool critical_hull) {
  straight_bipedal(agent, world, x0, y0,
                   BipedalSpec{.leg_down = 3 / kScale,
                               .leg_w = 8 / kScale,
                               .leg_h = 34 / kScale,
                               .hull_density = 5.0,
                               .leg_density = 1.0,
                               .critical_hull = critical_hull});
}

void build_small_bipedal(Agent& agent, b2World& world, double x0, double y0, bool critical_hull) {
  straight_bipedal(agent, world, x0, y0,
                   BipedalSpec{.leg_down = 3 / kScale,
                               .leg_w = 8 / kScale,
                               .leg_h = 17 / kScale,
                               .hull_density = 5.0,
                               .leg_density = 1.0,
                               .critical_hull = critical_hull});
}

void build_amphibious_bipedal(Agent& agent, b2World& world, double x0, double y0) {
  straight_bipedal(agent, world, x0, y0,
                   BipedalSpec{.leg_down = 3 / kScale,
                               .leg_w = 8 / kScale,
                               .leg_h = 34 / kScale,
                               .hull_density = 1.25 * kWaterDensity,
                               .leg_density = 0.25 * kWaterDensity,
                               .critical_hull = false,
                               .hull1 = {0.44f, 0.81f, 0.14f},
                               .hull2 = {0.36f, 0.66f, 0.11f},
                               .amphibian_colors = true});
}

// The hull both big quadrupeds share (they differ only in how their legs hang from it).
b2Body* build_quadru_hull(Agent& agent, b2World& world, double x0, double y0, bool critical_hull) {
  agent.torque = 300;
  agent.torque_penalty = 3.5e-4 / 2;
  const b2PolygonShape hull_shape =
      build::pixel_polygon({{-46, 13}, {6, 13}, {50, 5}, {50, -12}, {-46, -12}});
  b2Body* hull =
      build::part(agent, world, at(x0, y0), 0, hull_shape, Fixture{.density = 5.0, .friction = 0.1},
                  true, critical_hull, kHull1, kHull2);
  agent.head = hull;
  agent.pushed.push_back(hull);
  return hull;
}

void build_old_big_quadru(Agent& agent, b2World& world, double x0, double y0, bool critical_hull) {
  b2Body* hull = build_quadru_hull(agent, world, x0, y0, critical_hull);
  const double leg_down = -8 / kScale, leg_w = 10 / kScale, leg_h = 51 / kScale;
  const double half_bottom = 96 / 2 / kScale;
  const b2PolygonShape leg_shape = build::box(leg_w / 2, leg_h / 2);
  const b2PolygonShape lower_shape = build::box(0.8 * leg_w / 2, leg_h / 2);
  // The local anchor x is used raw while the spawn x is np.interp'ed (and clamped) onto the hull.
  for (double x_anchor : {-1.2, 0.85}) {
    const double ax = x0 + std::clamp(x_anchor, -1.0, 1.0) * half_bottom;
    for (double i : {-1.0, 1.0}) {
      b2Body* leg = build::part(agent, world, at(ax, y0 - leg_h / 2 - leg_down), i * 0.05,
                                leg_shape, Fixture{}, false, false, leg1(i), leg2(i));
      build::motor(
          agent,
          build::joint_local(world, hull, leg, at(x_anchor, leg_down), at(0, leg_h / 2), -0.8, 1.1),
          4);
      b2Body* lower = build::part(agent, world, at(ax, y0 - leg_h * 1.5 - leg_down), i * 0.05,
                                  lower_shape, Fixture{}, true, false, leg1(i), leg2(i));
      build::motor(
          agent,
          build::joint_local(world, leg, lower, at(0, -leg_h / 2), at(0, leg_h / 2), -1.6, -0.1), 6,
          lower, 1.0);
    }
  }
}

void build_spider(Agent& agent, b2World& world, double x0, double y0, bool critical_hull) {
  agent.torque = 100;
  agent.torque_penalty = 3.5e-4 / 2;
  const double h = 10 / kScale;  // half leg length
  const b2PolygonShape main_shape =
      build::pixel_polygon({{-10, 10}, {10, 10}, {10, -10}, {-10, -10}});
  b2Body* main =
      build::part(agent, world, at(x0, y0), 0, main_shape, Fixture{.density = 5.0, .friction = 0.1},
                  true, critical_hull, kHull1, kHull2);
  agent.head = main;
  agent.pushed.push_back(main);
  const b2PolygonShape upper_shape = build::box(3 / kScale, h);
  const b2PolygonShape lower_shape = build::box(2.4 / kScale, h);
  // Legs 0 and 2 (and 1 and 3) are identical and overlap; own parts never collide.
  for (double s : {1.0, -1.0, 1.0, -1.0}) {
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
  const int bodies = 4;
  agent.torque_penalty = 3.5e-4 / bodies;
  const double leg_down = 3 / kScale, leg_w = 4 / kScale, leg_h = 10 / kScale;
  const double seg = 20 / kScale;
  const b2PolygonShape main_shape =
      build::pixel_polygon({{-10, 10}, {10, 10}, {10, -10}, {-10, -10}});
  const b2PolygonShape leg_shape = build::box(leg_w / 2, leg_h / 2);
  const b2PolygonShape lower_shape = build::box(0.8 * leg_w / 2, leg_h / 2);
  const double left = x0 - seg * bodies / 2;
  b2Body* previous = nullptr;
  for (int j = 0; j < bodies; ++j) {
    const double bx = left + j * seg;
    // Segments check contact but are never critical (the reference sets an unused attribute).
    b2Body* main =
        build::part(agent, world, at(bx, y0), 0, main_shape,
                    Fixture{.density = 5.0, .friction = 0.1}, true, false, kHull1, kHull2);
    agent.pushed.push_back(main);
    for (double i : {-1.0, 1.0}) {
      b2Body* leg = build::part(agent, world, at(bx, y0 - leg_h / 2 - leg_down), 0, leg_shape,
                                Fixture{}, false, false, leg1(i), leg2(i));
      build::motor(agent, build::joint(world, main, leg, at(bx, y0 - leg_down), -0.8, 1.1, true),
                   4);
      b2Body* lower = build::part(agent, world, at(bx, y0 - leg_h * 1.5 - leg_down), 0, lower_shape,
                                  Fixture{}, true, false, leg1(i), leg2(i));
      build::motor(agent,
                   build::joint(world, leg, lower, at(bx, y0 - leg_down - leg_h), -1.6, -0.1, true),
                   6, lower, 1.0);
    }
    if (previous) {
      build::joint(world, previous, main, at(bx - seg / 2, y0), -0.05 * kPi, 0.05 * kPi, false);
    }
    previous = main;
  }
  agent.head = previous;  // the rightmost segment
}

void build_profile_chimpanzee(Agent& agent, b2World& world, double x0, double y0) {
  agent.torque = 100;
  agent.torque_penalty = 3.5e-4 / 5;
  agent.remove_head_angle = true;
  const double leg_down = 12 / kScale, arm_up = 22 / kScale;
  const double limb_w = 8 / kScale, limb_h = 28 / kScale, hand_w = 4 / kScale, hand_h = 8 / kScale;
  const Fixture body_fd{.density = 5.0, .friction = 0.1, .mask = 0x1};
  const Fixture limb_fd{.mask = 0x1};
  b2Body* torso = build::chimpanzee_trunk(agent, world, x0, y0, body_fd, kHull1, kHull2);
  const b2PolygonShape upper_shape = build::box(limb_w / 2, limb_h / 2);
  const b2PolygonShape lower_shape = build::box(0.8 * limb_w / 2, limb_h / 2);
  const b2PolygonShape hand_shape = build::box(hand_w / 2, hand_h / 2);
  for (int k = 0; k < 2; ++k) {
    b2Body* upper = build::part(agent, world, at(x0, y0 - limb_h / 2 - leg_down), 0, upper_shape,
                                limb_fd, false, false, leg1(1), leg2(1));
    build::motor(
        agent,
        build::joint(world, torso, upper, at(x0, y0 - leg_down), -0.3 * kPi, 0.6 * kPi, true), 4);
    b2Body* lower = build::part(agent, world, at(x0, y0 - limb_h * 1.5 - leg_down), 0, lower_shape,
                                limb_fd, true, false, leg1(1), leg2(1));
    build::motor(
        agent,
        build::joint(world, upper, lower, at(x0, y0 - limb_h - leg_down), -0.75 * kPi, -0.1, true),
        6, lower, 1.0);
  }
  const double hand_limits[3][2] = {{-0.4, 0.35}, {-0.5, 0}, {-0.8, 0}};
  for (int k = 0; k < 2; ++k) {
    b2Body* upper = build::part(agent, world, at(x0, y0 - limb_h / 2 + arm_up), 0, upper_shape,
                                limb_fd, false, false, leg1(-1), leg2(-1));
    build::motor(
        agent, build::joint(world, torso, upper, at(x0, y0 + arm_up), -0.5 * kPi, 0.8 * kPi, true),
        4);
    b2Body* lower = build::part(agent, world, at(x0, y0 - limb_h * 1.5 + arm_up), 0, lower_shape,
                                limb_fd, false, false, leg1(-1), leg2(-1));
    build::motor(
        agent, build::joint(world, upper, lower, at(x0, y0 - limb_h + arm_up), 0, 0.75 * kPi, true),
        4);
    b2Body* previous = lower;
    const double y_hand = y0 - limb_h * 2 + arm_up;
    for (int u = 0; u < 3; ++u) {
      b2Body* hand = build::part(agent, world, at(x0, y_hand - hand_h / 2 - hand_h * u), 0,
                                 hand_shape, limb_fd, true, false, leg1(-1), leg2(-1));
      build::motor(agent,
                   build::joint(world, previous, hand, at(x0, y_hand - hand_h * u),
                                hand_limits[u][0] * kPi, hand_limits[u][1] * kPi, true),
                   8, hand, 0);
      previous = hand;
    }
  }
}

void build_big_quadru(Agent& agent, b2World& world, double x0, double y0, bool critical_hull) {
  b2Body* hull = build_quadru_hull(agent, world, x0, y0, critical_hull);
  const double leg_down = 3 / kScale, leg_w = 10 / kScale, leg_h = 51 / kScale;
  const double half_bottom = 96 / 2 / kScale;
  const b2PolygonShape leg_shape = build::box(leg_w / 2, leg_h / 2);
  const b2PolygonShape lower_shape = build::box(0.8 * leg_w / 2, leg_h / 2);
  // Straight legs hanging from two points of the hull, world anchors.
  for (double x_anchor : {-0.7, 0.5}) {
    const double ax = x0 + x_anchor * half_bottom;
    for (double i : {-1.0, 1.0}) {
      b2Body* leg = build::part(agent, world, at(ax, y0 - leg_h / 2 - leg_down), 0, leg_shape,
                                Fixture{}, false, false, leg1(i), leg2(i));
      build::motor(agent, build::joint(world, hull, leg, at(ax, y0 - leg_down), -0.8, 1.1, true),
                   4);
      b2Body* lower = build::part(agent, world, at(ax, y0 - leg_h * 1.5 - leg_down), 0, lower_shape,
                                  Fixture{}, true, false, leg1(i), leg2(i));
      build::motor(agent,
                   build::joint(world, leg, lower, at(ax, y0 - leg_down - leg_h), -1.6, -0.1, true),
                   6, lower, 1.0);
    }
  }
}

void build_wheel(Agent& agent, b2World& world, double x0, double y0, bool critical_hull) {
  agent.torque = 500;
  agent.torque_penalty = 3.5e-4 / 2;
  agent.remove_head_angle = true;
  const double leg_w = 4 / kScale, leg_h = 10 / kScale, half = 10 / kScale;
  const Rgb body1{0.5f, 0.2f, 0.4f}, body2{0.3f, 0.1f, 0.2f};
  const Rgb limb1{0.7f, 0.4f, 0.6f}, limb2{0.5f, 0.3f, 0.4f};
  const b2PolygonShape main_shape =
      build::pixel_polygon({{-10, 10}, {10, 10}, {10, -10}, {-10, -10}});
  b2Body* main =
      build::part(agent, world, at(x0, y0), 0, main_shape, Fixture{.density = 5.0, .friction = 0.1},
                  true, critical_hull, body1, body2);
  agent.head = main;
  agent.pushed.push_back(main);
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

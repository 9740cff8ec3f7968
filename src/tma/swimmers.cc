// Swimmers: the fish. Every part has density water - 0.01 so it floats slightly; the body
// receives no initial push (the reference draws the force but does not apply it).
#include <cmath>
#include <numbers>

#include "tma/agent.h"

namespace cradle::tma {

void build_fish(Agent& agent, b2World& world, double x0, double y0) {
  using build::Fixture;
  constexpr double kPi = std::numbers::pi;
  agent.torque = 80;
  agent.torque_penalty = 3.5e-4;
  agent.remove_head_angle = true;
  const double density = kWaterDensity - 0.01;
  const Rgb c1{0.5f, 0.4f, 0.9f}, c2{0.3f, 0.3f, 0.5f};
  const Rgb b1{0.5f, 0.4f, 0.9f}, b2{0.3f, 0.3f, 0.5f};
  const b2PolygonShape head_shape =
      build::pixel_polygon({{-20, 12}, {6, 12}, {15, 4}, {15, -4}, {6, -12}, {-20, -12}});
  b2Body* hull = build::part(agent, world, at(x0, y0), 0, head_shape,
                             Fixture{.density = density, .friction = 0.1}, true, false, c1, c2);
  agent.head = hull;
  const Fixture part_fd{.density = density};
  // Body segments chained behind the head (spawn x, shape, local anchors on the previous part and
  // on the segment, joint limits in pi); every joint is a contact-checking motor.
  struct Segment {
    double x;
    b2PolygonShape shape;
    double anchor_a, anchor_b, lower, upper;
  };
  const Segment segments[] = {
      {x0 - 0.85, build::pixel_polygon({{-8, 9}, {8, 12}, {8, -12}, {-8, -9}}), -17.5, 8, -0.1,
       0.2},
      {x0 - 41.5 / kScale, build::pixel_polygon({{-8, 4}, {8, 9}, {8, -9}, {-8, -4}}), -8, 8, -0.15,
       0.15},
      {x0 - 53.5 / kScale, build::pixel_polygon({{-4, 2}, {4, 4}, {4, -4}, {-4, -2}}), -8, 4, -0.3,
       0.3},
  };
  b2Body* previous = hull;
  for (const Segment& g : segments) {
    b2Body* segment =
        build::part(agent, world, at(g.x, y0), 0, g.shape, part_fd, true, false, b1, b2);
    build::motor(agent,
                 build::joint_local(world, previous, segment, at(g.anchor_a / kScale, 0),
                                    at(g.anchor_b / kScale, 0), g.lower * kPi, g.upper * kPi),
                 6, segment);
    previous = segment;
  }
  // The fin hangs under the head, tilted back by 0.2 pi.
  const b2PolygonShape fin_shape = build::box(1 / kScale, 10 / kScale);
  const double fin_angle = -0.2 * kPi, fin_h = 10 / kScale;
  const double fin_x = x0 + fin_h * std::sin(fin_angle);
  const double fin_y = y0 - 5 / kScale - fin_h * std::cos(fin_angle);
  b2Body* fin = build::part(agent, world, at(fin_x, fin_y), fin_angle, fin_shape, part_fd, true,
                            false, b1, b2);
  build::motor(agent,
               build::joint_local(world, hull, fin, at(0, -5 / kScale), at(0, 10 / kScale),
                                  -0.3 * kPi, 0.2 * kPi),
               6, fin);
}

}  // namespace cradle::tma

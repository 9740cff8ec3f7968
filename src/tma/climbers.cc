// Climbers: the climbing profile chimpanzee (legs) and its chest-only variant. Hands end in a
// sensor circle welded to the hand; the grasp actions weld it to a creeper or the ceiling
// (climbing.cc). Every fixture collides with terrain only (mask 0x1).
#include <numbers>

#include "tma/agent.h"

namespace cradle::tma {

void build_climbing_chimpanzee(Agent& agent, b2World& world, double x0, double y0, bool legs) {
  using build::Fixture;
  constexpr double kPi = std::numbers::pi;
  auto at = [](double x, double y) { return b2Vec2(static_cast<float>(x), static_cast<float>(y)); };
  const Rgb hull1{0.5f, 0.4f, 0.9f}, hull2{0.3f, 0.3f, 0.5f};
  const Rgb limb1{0.5f, 0.2f, 0.4f}, limb2{0.3f, 0.1f, 0.2f};
  const Rgb arm1{0.7f, 0.4f, 0.6f}, arm2{0.5f, 0.3f, 0.4f};
  agent.torque = 100;
  agent.torque_penalty = 3.5e-4 / 5;
  agent.remove_head_angle = true;
  const double leg_down = 12 / kScale, arm_up = 22 / kScale;
  const double limb_w = 8 / kScale, limb_h = 28 / kScale, hand_w = 4 / kScale, hand_h = 8 / kScale;
  const Fixture body_fd{.density = 5.0, .friction = 0.1, .mask = 0x1};
  const Fixture limb_fd{.mask = 0x1};

  // Head (reference object, critical) floats above the torso, held by a passive neck.
  b2Body* torso = build::chimpanzee_trunk(agent, world, x0, y0, body_fd, hull1, hull2);

  const b2PolygonShape upper_shape = build::box(limb_w / 2, limb_h / 2);
  const b2PolygonShape lower_shape = build::box(0.8 * limb_w / 2, limb_h / 2);
  const b2PolygonShape hand_shape = build::box(hand_w / 2, hand_h / 2);
  // Two identical legs (they overlap at spawn, as in the reference); lower legs are critical.
  if (legs) {
    for (int k = 0; k < 2; ++k) {
      b2Body* upper = build::part(agent, world, at(x0, y0 - limb_h / 2 - leg_down), 0, upper_shape,
                                  limb_fd, false, false, limb1, limb2);
      build::motor(
          agent,
          build::joint(world, torso, upper, at(x0, y0 - leg_down), -0.3 * kPi, 0.6 * kPi, true), 4);
      b2Body* lower = build::part(agent, world, at(x0, y0 - limb_h * 1.5 - leg_down), 0,
                                  lower_shape, limb_fd, true, true, limb1, limb2);
      build::motor(agent,
                   build::joint(world, upper, lower, at(x0, y0 - limb_h - leg_down), -0.75 * kPi,
                                -0.1, true),
                   6, lower, 1.0);
    }
  }
  // Two identical arms raised above the torso, each: shoulder, elbow, wrist, then the sensor.
  b2CircleShape sensor_shape;
  sensor_shape.m_radius = static_cast<float>(1.5 / kScale);
  for (int k = 0; k < 2; ++k) {
    b2Body* upper = build::part(agent, world, at(x0, y0 + limb_h / 2 + arm_up), 0, upper_shape,
                                limb_fd, false, false, arm1, arm2);
    build::motor(agent, build::joint(world, torso, upper, at(x0, y0 + arm_up), -1.5 * kPi, 0, true),
                 4);
    b2Body* lower = build::part(agent, world, at(x0, y0 + limb_h * 1.5 + arm_up), 0, lower_shape,
                                limb_fd, false, false, arm1, arm2);
    build::motor(
        agent, build::joint(world, upper, lower, at(x0, y0 + limb_h + arm_up), 0, 0.75 * kPi, true),
        4);
    const double y_hand = y0 + limb_h * 2 + arm_up;
    b2Body* hand = build::part(agent, world, at(x0, y_hand + hand_h / 2), 0, hand_shape, limb_fd,
                               true, false, arm1, arm2);
    build::motor(agent,
                 build::joint(world, lower, hand, at(x0, y_hand), -0.5 * kPi, 0.5 * kPi, true), 8,
                 hand, 0);
    // The sensor is not a body part: it is created like one, then moved to `sensors`.
    const b2Vec2 sensor_pos = at(x0, y_hand + hand_h);
    b2Body* sensor = build::part(agent, world, sensor_pos, 0, sensor_shape,
                                 Fixture{.density = 1.0, .mask = 0x1, .sensor = true}, true, false,
                                 Rgb{1, 0, 0}, Rgb{1, 0, 0});
    agent.parts.pop_back();
    Tag* tag = tag_of(sensor);
    tag->type = ObjectType::kBodySensor;
    tag->sensor = static_cast<int>(agent.sensors.size());
    agent.sensors.push_back(Sensor{.body = sensor, .tag = tag});
    agent.sensors.back().touching.reserve(8);
    b2WeldJointDef weld;
    weld.Initialize(hand, sensor, sensor_pos);
    world.CreateJoint(&weld);
  }
}

}  // namespace cradle::tma

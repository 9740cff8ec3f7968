// Climbers: the climbing profile chimpanzee (legs) and its chest-only variant. Hands end in a
// sensor circle welded to the hand; the grasp actions weld it to a creeper or the ceiling
// (climbing.cc). Every fixture collides with terrain only (mask 0x1).
#include <numbers>

#include "tma/agent.h"

namespace cradle::tma {

void build_climbing_chimpanzee(Agent& agent, b2World& world, double x0, double y0, bool legs) {
  using build::Fixture;
  constexpr double kPi = std::numbers::pi;
  const Rgb arm1{0.7f, 0.4f, 0.6f}, arm2{0.5f, 0.3f, 0.4f};
  // Lower legs are critical.
  const build::Chimpanzee c = build::chimpanzee(agent, world, x0, y0, legs, true);
  const double arm_up = c.kArmUp, limb_h = c.kLimbH, hand_h = c.kHandH;
  // Two identical arms raised above the torso, each: shoulder, elbow, wrist, then the sensor.
  b2CircleShape sensor_shape;
  sensor_shape.m_radius = static_cast<float>(1.5 / kScale);
  for (int k = 0; k < 2; ++k) {
    b2Body* upper = build::part(agent, world, at(x0, y0 + limb_h / 2 + arm_up), 0, c.upper,
                                c.limb_fd, false, false, arm1, arm2);
    build::motor(agent,
                 build::joint(world, c.torso, upper, at(x0, y0 + arm_up), -1.5 * kPi, 0, true), 4);
    b2Body* lower = build::part(agent, world, at(x0, y0 + limb_h * 1.5 + arm_up), 0, c.lower,
                                c.limb_fd, false, false, arm1, arm2);
    build::motor(
        agent, build::joint(world, upper, lower, at(x0, y0 + limb_h + arm_up), 0, 0.75 * kPi, true),
        4);
    const double y_hand = y0 + limb_h * 2 + arm_up;
    b2Body* hand = build::part(agent, world, at(x0, y_hand + hand_h / 2), 0, c.hand, c.limb_fd,
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

// TeachMyAgent's shared Box2D setup: units, step, terrain geometry, object types and the record
// each body carries in its user data (what the contact listener, lidars and renderer read).
#pragma once

#include <box2d/box2d.h>

#include <cstdint>

namespace cradle::tma {

// Scale and timing: pixel constants of the reference are divided by kScale.
inline constexpr double kScale = 30.0;
inline constexpr double kFps = 50.0;
inline constexpr int kVelocityIterations = 180;
inline constexpr int kPositionIterations = 60;
inline constexpr double kViewportW = 600.0, kViewportH = 400.0;

// Terrain geometry (world units).
inline constexpr double kTerrainStep = 14.0 / kScale;
inline constexpr int kTerrainLength = 200;  // in steps
inline constexpr double kTerrainHeight = kViewportH / kScale / 4.0;
inline constexpr int kStartpad = 20;  // in steps
inline constexpr double kFriction = 2.5;
inline constexpr double kWaterDensity = 1.0;

// Lidars.
inline constexpr int kLidars = 10;
inline constexpr double kLidarRange = 160.0 / kScale;

// Episode.
inline constexpr int kMaxEpisodeSteps = 2000;
inline constexpr double kSuccessReturn = 230.0;
inline constexpr int kSurviveSteps = 600;  // under water (walkers, climbers) / out (swimmers)

// Filter bits.
inline constexpr std::uint16_t kTerrainBits = 0x1;
inline constexpr std::uint16_t kAgentBits = 0x20;

// What a body is (the reference's CustomUserDataObjectTypes).
enum class ObjectType : std::uint8_t {
  kBody = 0,
  kWater = 1,
  kTerrain = 2,
  kGripTerrain = 3,
  kBodySensor = 5,
  kCreeper = 6,
};

struct Rgb {
  float r = 0, g = 0, b = 0;
};

// The record behind b2BodyUserData::pointer: type, contact flags and drawing colours.
struct Tag {
  ObjectType type = ObjectType::kTerrain;
  bool check_contact = false;
  bool critical = false;
  bool has_contact = false;
  // Hand sensors only.
  bool has_joint = false;
  bool ready = false;
  int sensor = -1;  // index in Agent::sensors
  Rgb color1, color2;
};

// A point in world units at full precision.
struct WorldPoint {
  double x = 0, y = 0;
};

// A point in world units as Box2D's float vector.
inline b2Vec2 at(double x, double y) {
  return b2Vec2(static_cast<float>(x), static_cast<float>(y));
}

inline Tag* tag_of(const b2Body* body) {
  return reinterpret_cast<Tag*>(const_cast<b2Body*>(body)->GetUserData().pointer);
}

// Revolute limits as Box2D 2.3 (the reference's engine) solves them; call before every world step.
// 2.3 decides each step, from the angle at its start, whether a limit takes part: a joint strictly
// inside its limits is free for the whole step and may overshoot, and one at or past a limit is
// held there with no velocity bias while the position pass pulls it back only to b2_angularSlop
// (0.035 rad) past the limit. A motor-held joint therefore rests 0.026-0.033 rad past its limit,
// outside the limits that the water push tests. 2.4.1 instead solves a limit speculatively, so the
// joint stops at the limit (within 0.0005 rad) and reads inside on many held steps: pinned fish
// fins kept pushing and the sine-gait fish swam backwards. Enabling a limit only while the joint is
// at or past it gives back 2.3's rule through 2.4.1's public API: 2.4.1's limit pass with the angle
// past the limit has no bias, and its position pass is 2.3's. Every limited joint of these envs has
// lower < upper; a joint without a limit keeps lower = upper = 0 and is left alone. Limits closer
// than 2 b2_angularSlop stay on, as 2.3 holds such a joint at all times.
inline void box2d23_limits(b2World& world) {
  for (b2Joint* j = world.GetJointList(); j; j = j->GetNext()) {
    if (j->GetType() != e_revoluteJoint) continue;
    auto* joint = static_cast<b2RevoluteJoint*>(j);
    const float lower = joint->GetLowerLimit(), upper = joint->GetUpperLimit();
    if (!(lower < upper)) continue;
    const float angle = joint->GetJointAngle();
    joint->EnableLimit(upper - lower < 2.0f * b2_angularSlop || angle <= lower || angle >= upper);
  }
}

}  // namespace cradle::tma

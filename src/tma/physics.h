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

// A point in world units as Box2D's float vector.
inline b2Vec2 at(double x, double y) {
  return b2Vec2(static_cast<float>(x), static_cast<float>(y));
}

inline Tag* tag_of(const b2Body* body) {
  return reinterpret_cast<Tag*>(const_cast<b2Body*>(body)->GetUserData().pointer);
}

}  // namespace cradle::tma

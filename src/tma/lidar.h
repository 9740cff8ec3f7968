// Lidars: 10 rays from the head origin; each reports the fraction of the ray to the closest fixture
// the head's mask can see (sensors included: water and creepers) and what it hit.
#pragma once

#include <box2d/box2d.h>

#include <array>
#include <cstdint>

#include "tma/physics.h"

namespace cradle::tma {

enum class LidarType { kDown, kUp, kFull };

struct LidarReading {
  float fraction = 1.0f;
  int code = 0;  // -1 water, +1 creeper, 0 otherwise
  b2Vec2 p1, p2;
};

// Angle theta_i = A * i / 10 + B from straight down towards +x.
void lidar_fan(LidarType type, double* a, double* b);
void cast_lidars(const b2World& world, const b2Vec2& origin, std::uint16_t mask, LidarType type,
                 std::array<LidarReading, kLidars>& out);

}  // namespace cradle::tma

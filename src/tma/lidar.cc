#include "tma/lidar.h"

#include <cmath>
#include <numbers>

namespace cradle::tma {
namespace {

class Callback : public b2RayCastCallback {
 public:
  Callback(std::uint16_t mask, LidarReading& reading) : mask_(mask), reading_(reading) {}
  float ReportFixture(b2Fixture* fixture, const b2Vec2& point, const b2Vec2&,
                      float fraction) override {
    // Agent parts (category 0x20) are invisible to the agent's own mask.
    if ((fixture->GetFilterData().categoryBits & mask_) == 0) return -1;
    reading_.p2 = point;
    reading_.fraction = fraction;
    const ObjectType type = tag_of(fixture->GetBody())->type;
    reading_.code = type == ObjectType::kWater ? -1 : (type == ObjectType::kCreeper ? 1 : 0);
    return fraction;
  }

 private:
  std::uint16_t mask_;
  LidarReading& reading_;
};

}  // namespace

void lidar_fan(LidarType type, double* a, double* b) {
  switch (type) {
    case LidarType::kDown:
      *a = 1.5, *b = 0;
      return;
    case LidarType::kUp:
      *a = 2.3, *b = 1.5;
      return;
    case LidarType::kFull:
      *a = std::numbers::pi, *b = 0;
      return;
  }
}

void cast_lidars(const b2World& world, const b2Vec2& origin, std::uint16_t mask, LidarType type,
                 std::array<LidarReading, kLidars>& out) {
  double a, b;
  lidar_fan(type, &a, &b);
  for (int i = 0; i < kLidars; ++i) {
    const double theta = a * i / kLidars + b;
    LidarReading& r = out[i];
    r.fraction = 1.0f;
    r.code = 0;
    r.p1 = origin;
    const b2Vec2 end(static_cast<float>(origin.x + std::sin(theta) * kLidarRange),
                     static_cast<float>(origin.y - std::cos(theta) * kLidarRange));
    r.p2 = end;
    Callback callback(mask, r);
    world.RayCast(&callback, origin, end);
  }
}

}  // namespace cradle::tma

// Dynamics: water (buoyancy, the fish's survival out of water), climbing grasps, lidars, terrain.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "tma/tma_env.h"
#include "tma/water.h"

namespace cradle::tma {
namespace {

TmaEnv make(EnvId env, const char* body) { return TmaEnv(TmaOptions{.env = env, .body = body}); }

// A fish in a full pool with zero action floats (density 0.99): it does not reach the floor.
TEST(TmaWater, FishInWaterDoesNotSink) {
  TmaEnv env = make(EnvId::kParkour, "fish");
  env.set_environment({{"input_vector", {0.0, 0.0, 0.0}}, {"water_level", {1.0}}});
  env.reset(1);
  const double y0 = env.agent().head->GetPosition().y;
  const std::vector<double> zero(4, 0.0);
  for (int t = 0; t < 200; ++t) env.step(zero);
  const double y = env.agent().head->GetPosition().y;
  EXPECT_GT(y, y0 - 0.05);
  EXPECT_EQ(env.observation()[4], 1.0);  // under water
  for (int k = 0; k < 4; ++k) EXPECT_EQ(env.observation()[8 + 3 * k], 0.0) << "part on the floor";
}

// Without buoyancy a body of density 0.99 falls: the same fish in (almost) no water hits ground.
TEST(TmaWater, FishOutOfWaterStopsActingAfter600Steps) {
  TmaEnv env = make(EnvId::kParkour, "fish");
  env.set_environment({{"input_vector", {0.0, 0.0, 0.0}}, {"water_level", {0.0}}});
  env.reset(2);
  const std::vector<double> push(4, 1.0);
  for (int t = 0; t < 601; ++t) env.step(push);
  EXPECT_EQ(env.observation()[5], 0.0);
  EXPECT_GT(env.agent().motors[0].joint->GetMaxMotorTorque(), 0.0f);
  env.step(push);
  EXPECT_EQ(env.observation()[5], 1.0);  // dead
  EXPECT_EQ(env.agent().motors[0].joint->GetMaxMotorTorque(), 0.0f);
  env.step(push);
  EXPECT_TRUE(env.dead());
}

TEST(TmaWater, ClipAndCentroidOfASquare) {
  const b2Vec2 water[4] = {{0, -10}, {10, -10}, {10, 1}, {0, 1}};
  const b2Vec2 body[4] = {{1, 0}, {3, 0}, {3, 2}, {1, 2}};  // half below y = 1
  b2Vec2 out[32];
  const int n = clip_polygon(water, 4, body, 4, out, 32);
  b2Vec2 c;
  const float area = polygon_area_centroid(out, n, &c);
  EXPECT_NEAR(area, 2.0, 1e-5);
  EXPECT_NEAR(c.x, 2.0, 1e-5);
  EXPECT_NEAR(c.y, 0.5, 1e-5);
}

// The climber starts hanging from the ceiling; while it holds, it stays up; released, it falls.
TEST(TmaClimbing, GraspHoldsTheClimberAndReleaseDropsIt) {
  TmaEnv env = make(EnvId::kParkour, "climbing_profile_chimpanzee");
  env.set_environment({{"input_vector", {0.0, 0.0, 0.0}}, {"water_level", {0.0}}});
  env.reset(5);
  const auto obs = env.observation();
  EXPECT_EQ(obs[31], 1.0);  // sensor 0 has a joint
  EXPECT_EQ(obs[33], 1.0);  // sensor 1 has a joint
  std::vector<double> hold(12, 0.0);
  hold[10] = hold[11] = 1.0;
  const double y0 = env.agent().head->GetPosition().y;
  for (int t = 0; t < 100; ++t) EXPECT_FALSE(env.step(hold).terminated);
  EXPECT_NEAR(env.agent().head->GetPosition().y, y0, 0.5);
  std::vector<double> release(12, 0.0);
  release[10] = release[11] = -1.0;
  for (int t = 0; t < 40; ++t) env.step(release);
  EXPECT_EQ(env.observation()[31], 0.0);
  EXPECT_LT(env.agent().head->GetPosition().y, y0 - 1.0);
}

// Released inside a long creeper, the climber grasps the creeper itself and hangs there.
TEST(TmaClimbing, GraspHoldsOnACreeper) {
  TmaEnv env = make(EnvId::kParkour, "climbing_profile_chimpanzee");
  env.set_environment({{"input_vector", {0.0, 0.0, 0.0}},
                       {"water_level", {0.0}},
                       {"creepers_width", {0.25}},
                       {"creepers_height", {4.0}},
                       {"creepers_spacing", {0.01}}});
  env.reset(5);
  std::vector<double> a(12, 0.0);
  a[10] = a[11] = -1.0;
  for (int t = 0; t < 8; ++t) env.step(a);
  a[10] = a[11] = 1.0;
  for (int t = 0; t < 60; ++t) env.step(a);
  bool on_creeper = false;
  for (const Sensor& s : env.agent().sensors) {
    if (s.grasp) on_creeper |= tag_of(s.grasp->GetBodyB())->type == ObjectType::kCreeper;
  }
  EXPECT_TRUE(on_creeper);
  const double y = env.agent().head->GetPosition().y;
  for (int t = 0; t < 50; ++t) env.step(a);
  EXPECT_NEAR(env.agent().head->GetPosition().y, y, 0.3);
}

// Lidar fractions over flat ground equal the geometric distance to the ground line.
TEST(TmaLidar, FractionsEqualGeometricDistances) {
  TmaEnv env = make(EnvId::kStumpTracks, "old_classic_bipedal");
  env.set_environment({{"stump_height", {2.0}}, {"obstacle_spacing", {6.0}}});
  env.reset(0);
  const b2Vec2 p = env.agent().head->GetPosition();
  const double first_stump = kStartpad * kTerrainStep;
  int checked = 0;
  for (int i = 0; i < kLidars; ++i) {
    const double theta = 1.5 * i / kLidars;
    const double dist = (p.y - kTerrainHeight) / std::cos(theta);
    if (dist > kLidarRange || p.x + dist * std::sin(theta) > first_stump - 0.1) continue;
    EXPECT_NEAR(env.observation()[14 + i], dist / kLidarRange, 1e-4) << "ray " << i;
    ++checked;
  }
  EXPECT_GE(checked, 5);
}

// Parkour: a ray entering water from above reports it with code -1 at the surface distance.
TEST(TmaLidar, WaterIsSeenWithCodeMinusOne) {
  TmaEnv env = make(EnvId::kParkour, "old_classic_bipedal");
  env.set_environment({{"input_vector", {0.0, 0.0, 0.0}}, {"water_level", {0.5}}});
  env.reset(0);
  const Scene& s = env.scene();
  const double top = *std::max_element(s.ceiling.begin(), s.ceiling.end());
  const double target = kTerrainHeight + 1.0;  // one unit above the start pad
  const double level = (target - s.ground_limit) / (top - s.ground_limit);
  env.set_environment({{"water_level", {level}}});
  env.reset(0);
  const double y = env.agent().head->GetPosition().y;
  EXPECT_NEAR(env.observation()[16], (y - target) / kLidarRange, 1e-3);
  EXPECT_EQ(env.observation()[26], -1.0);
}

// Height 0: the ground is one flat line and stumps are at most a few tenths of a step tall.
TEST(TmaTerrain, StumpHeightZeroIsFlatGround) {
  TmaEnv env = make(EnvId::kStumpTracks, "small_bipedal");
  env.set_environment({{"stump_height", {0.0}}, {"obstacle_spacing", {0.5}}});
  env.reset(9);
  for (double y : env.scene().ground) EXPECT_EQ(y, kTerrainHeight);
  for (const b2Body* b : env.scene().bodies) {
    const auto* poly = static_cast<const b2PolygonShape*>(b->GetFixtureList()->GetShape());
    for (int k = 0; k < poly->m_count; ++k) {
      EXPECT_LE(poly->m_vertices[k].y, kTerrainHeight + 0.6 * kTerrainStep);
    }
  }
  // The walker then crosses the first 50 steps without a fatal contact.
  const std::vector<double> zero(4, 0.0);
  for (int t = 0; t < 50; ++t) EXPECT_FALSE(env.step(zero).terminated);
}

TEST(TmaTerrain, StumpCountsFollowTheSpacing) {
  for (auto [spacing, stumps] : {std::pair{6.0, 13}, std::pair{0.01, 177}}) {
    TmaEnv env = make(EnvId::kStumpTracks, "old_classic_bipedal");
    env.set_environment({{"stump_height", {1.0}}, {"obstacle_spacing", {spacing}}});
    env.reset(0);
    EXPECT_EQ(static_cast<int>(env.scene().bodies.size()), stumps) << spacing;
  }
}

// Parkour: 220 points, start pad flat, ceiling 20 above the ground at scale 10, and a fatal
// ground contact for the climbers' critical parts only.
TEST(TmaTerrain, ParkourTerrainShape) {
  TmaEnv env = make(EnvId::kParkour, "old_classic_bipedal");
  env.set_environment({{"input_vector", {-0.2, 0.9, 0.1}}, {"water_level", {0.0}}});
  env.reset(0);
  const Scene& s = env.scene();
  ASSERT_EQ(s.xs.size(), 220u);
  EXPECT_NEAR(s.xs.back(), 219 * kTerrainStep, 1e-9);
  for (int i = 0; i < 20; ++i) {
    EXPECT_EQ(s.ground[i], kTerrainHeight);
    EXPECT_NEAR(s.ceiling[i], kTerrainHeight + 20.0, 1e-9);
  }
  EXPECT_NEAR(s.ground[20], kTerrainHeight, 1e-6);  // the CPPN's first row is aligned to the pad
  for (size_t i = 0; i < s.xs.size(); ++i) EXPECT_GE(s.ceiling[i], s.ground[i]);
}

}  // namespace
}  // namespace cradle::tma

namespace cradle::tma {
namespace {

// Movable creepers: chains of dynamic 1-unit segments jointed to the ceiling edge; a climber
// still starts hanging and holds.
TEST(TmaClimbing, MovableCreepersAreDynamicChains) {
  TmaEnv env(TmaOptions{
      .env = EnvId::kParkour, .body = "climbing_profile_chimpanzee", .movable_creepers = true});
  env.set_environment({{"input_vector", {0.0, 0.0, 0.0}},
                       {"water_level", {0.0}},
                       {"creepers_width", {0.25}},
                       {"creepers_height", {2.5}},
                       {"creepers_spacing", {3.0}}});
  env.reset(4);
  int segments = 0;
  for (const b2Body* b : env.scene().bodies) {
    if (tag_of(b)->type != ObjectType::kCreeper) continue;
    EXPECT_EQ(b->GetType(), b2_dynamicBody);
    EXPECT_NE(b->GetJointList(), nullptr);
    ++segments;
  }
  EXPECT_GT(segments, 0);
  EXPECT_EQ(segments % 3, 0);  // ceil(2.5 +- noise) = 3 segments per creeper (noise sd 0.1)
  std::vector<double> hold(12, 0.0);
  hold[10] = hold[11] = 1.0;
  const double y0 = env.agent().head->GetPosition().y;
  for (int t = 0; t < 50; ++t) env.step(hold);
  EXPECT_NEAR(env.agent().head->GetPosition().y, y0, 0.5);
}

}  // namespace
}  // namespace cradle::tma

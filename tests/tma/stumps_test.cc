// Stump Tracks' optional task dimensions: stump width and rotation (N(mean, std) draws) and ground
// roughness (vertical velocity noise at every gap).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "tma/tma_env.h"

namespace cradle::tma {
namespace {

std::unique_ptr<TmaEnv> stumps(const std::vector<TaskParam>& task, std::uint64_t seed) {
  auto env = std::make_unique<TmaEnv>(
      TmaOptions{.env = EnvId::kStumpTracks, .body = "old_classic_bipedal"});
  env->set_environment(task);
  env->reset(seed);
  return env;
}

std::vector<b2Vec2> vertices(const b2Body* body) {
  const auto* poly = static_cast<const b2PolygonShape*>(body->GetFixtureList()->GetShape());
  return {poly->m_vertices, poly->m_vertices + poly->m_count};
}

// With std 0 every stump is turned by the mean: its bottom edge (length TERRAIN_STEP) keeps its
// middle at (x + w/2, ground) and points at the angle; the opposite edge is one height away.
TEST(TmaStumps, RotationTurnsEachStumpAboutItsBottomMiddle) {
  const double angle = 0.5;
  auto env = stumps(
      {{"stump_height", {2.0}}, {"obstacle_spacing", {3.0}}, {"stump_rot", {angle, 0.0}}}, 4);
  const Scene& scene = env->scene();
  ASSERT_GT(scene.bodies.size(), 5u);
  for (size_t i = 0; i < scene.bodies.size(); ++i) {
    const std::vector<b2Vec2> v = vertices(scene.bodies[i]);
    ASSERT_EQ(v.size(), 4u);
    const double ax = scene.xs[1 + 2 * i] + kTerrainStep / 2, ay = scene.ground[1 + 2 * i];
    int found = 0;
    for (int k = 0; k < 4; ++k) {
      const b2Vec2 a = v[k], b = v[(k + 1) % 4];
      const double mx = (a.x + b.x) / 2.0, my = (a.y + b.y) / 2.0;
      if (std::hypot(mx - ax, my - ay) > 1e-4) continue;
      ++found;
      EXPECT_NEAR(std::hypot(b.x - a.x, b.y - a.y), kTerrainStep, 1e-5);
      // The edge direction modulo pi equals the angle.
      const double dir = std::remainder(std::atan2(b.y - a.y, b.x - a.x) - angle, std::numbers::pi);
      EXPECT_NEAR(dir, 0.0, 1e-5);
    }
    EXPECT_EQ(found, 1) << "stump " << i;
    // A turned stump is no longer axis-aligned: its lowest vertex sits below the ground line.
    double low = 1e9;
    for (const b2Vec2& p : v) low = std::min<double>(low, p.y);
    EXPECT_LT(low, ay - 0.1);
  }
}

// Width mean 2, std 0: every stump is 2 TERRAIN_STEP wide and the recorded points follow it.
TEST(TmaStumps, WidthScalesEachStump) {
  auto narrow = stumps({{"stump_height", {1.0}}, {"obstacle_spacing", {2.0}}}, 3);
  auto wide = stumps(
      {{"stump_height", {1.0}}, {"obstacle_spacing", {2.0}}, {"stump_width", {2.0, 0.0}}}, 3);
  const Scene& scene = wide->scene();
  for (size_t i = 0; i < scene.bodies.size(); ++i) {
    double lo = 1e9, hi = -1e9;
    for (const b2Vec2& p : vertices(scene.bodies[i])) {
      lo = std::min<double>(lo, p.x);
      hi = std::max<double>(hi, p.x);
    }
    EXPECT_NEAR(hi - lo, 2 * kTerrainStep, 1e-5);
    EXPECT_NEAR(scene.xs[2 + 2 * i] - scene.xs[1 + 2 * i], 2 * kTerrainStep, 1e-9);
    EXPECT_NEAR(lo, scene.xs[1 + 2 * i], 1e-5);
  }
  // Wider stumps leave room for fewer of them on the same track.
  EXPECT_LT(scene.bodies.size(), narrow->scene().bodies.size());
  // The multiplier is floored at 0.05.
  auto thin = stumps({{"stump_height", {1.0}}, {"stump_width", {0.0, 0.0}}}, 3);
  EXPECT_NEAR(thin->scene().xs[2] - thin->scene().xs[1], 0.05 * kTerrainStep, 1e-9);
}

// Roughness 0 keeps the ground flat and the terrain equal to the benchmark's (no extra draw);
// roughness > 0 makes it uneven, and each stump stands on the ground where it begins.
TEST(TmaStumps, RoughnessMakesTheGroundUneven) {
  const std::vector<TaskParam> base{{"stump_height", {1.0}}, {"obstacle_spacing", {1.0}}};
  auto plain = stumps(base, 5);
  std::vector<TaskParam> flat = base;
  flat.push_back({"roughness", {0.0}});
  auto zero = stumps(flat, 5);
  for (double y : zero->scene().ground) EXPECT_EQ(y, kTerrainHeight);
  ASSERT_EQ(zero->scene().bodies.size(), plain->scene().bodies.size());
  for (size_t i = 0; i < plain->scene().bodies.size(); ++i) {
    const std::vector<b2Vec2> a = vertices(plain->scene().bodies[i]);
    const std::vector<b2Vec2> b = vertices(zero->scene().bodies[i]);
    for (size_t k = 0; k < a.size(); ++k) EXPECT_TRUE(a[k] == b[k]);
  }
  std::vector<TaskParam> rough = base;
  rough.push_back({"roughness", {5.0}});
  auto env = stumps(rough, 5);
  const Scene& scene = env->scene();
  double spread = 0;
  for (double y : scene.ground) spread = std::max(spread, std::abs(y - kTerrainHeight));
  EXPECT_GT(spread, 0.05);
  EXPECT_LT(spread, 10.0);  // the velocity relaxes towards TERRAIN_HEIGHT
  for (size_t i = 0; i < scene.bodies.size(); ++i) {
    double low = 1e9;
    for (const b2Vec2& p : vertices(scene.bodies[i])) low = std::min<double>(low, p.y);
    EXPECT_NEAR(low, scene.ground[1 + 2 * i], 1e-5);
  }
  // The start pad stays flat.
  EXPECT_EQ(scene.ground[0], kTerrainHeight);
  EXPECT_EQ(scene.ground[1], kTerrainHeight);
}

// Same seed and full task -> bitwise-identical terrain and trajectory; another seed differs.
TEST(TmaStumps, AllDimensionsAreDeterministic) {
  const std::vector<TaskParam> task{{"stump_height", {1.5}},
                                    {"obstacle_spacing", {2.0}},
                                    {"stump_width", {1.2, 0.3}},
                                    {"stump_rot", {0.3, 0.2}},
                                    {"roughness", {2.0}}};
  auto run = [&](std::uint64_t seed) {
    auto env = stumps(task, seed);
    std::vector<double> trace(env->scene().ground);
    for (const b2Body* b : env->scene().bodies)
      for (const b2Vec2& p : vertices(b)) trace.insert(trace.end(), {p.x, p.y});
    const std::vector<double> action{0.5, -0.3, 0.2, 0.8};
    for (int t = 0; t < 100; ++t) {
      env->step(action);
      trace.insert(trace.end(), env->observation().begin(), env->observation().end());
    }
    return trace;
  };
  const std::vector<double> a = run(11), b = run(11), c = run(12);
  EXPECT_TRUE(a == b);
  EXPECT_FALSE(a == c);
}

TEST(TmaStumps, BadOptionalValuesAreOneLineErrors) {
  TmaEnv env(TmaOptions{.env = EnvId::kStumpTracks});
  auto message = [&](const std::vector<TaskParam>& task) {
    try {
      env.set_environment(task);
    } catch (const std::exception& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.find('\n'), std::string::npos);
      return m;
    }
    ADD_FAILURE() << "no error";
    return std::string();
  };
  EXPECT_NE(message({{"stump_width", {1.0}}}).find("2 values"), std::string::npos);
  EXPECT_NE(message({{"stump_width", {1.0, NAN}}}).find("stump_width std"), std::string::npos);
  EXPECT_NE(message({{"stump_rot", {7.0, 0.1}}}).find("stump_rot mean"), std::string::npos);
  EXPECT_NE(message({{"roughness", {-1.0}}}).find("roughness"), std::string::npos);
  EXPECT_NE(message({{"roughness", {INFINITY}}}).find("roughness"), std::string::npos);
  EXPECT_NE(message({{"stump_tilt", {0.1}}}).find("stump_rot"), std::string::npos);
  // A failed call leaves the task unchanged.
  EXPECT_FALSE(env.stump_task().stump_width.has_value());
  EXPECT_EQ(env.stump_task().roughness, 0.0);
}

}  // namespace
}  // namespace cradle::tma

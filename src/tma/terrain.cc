#include "tma/terrain.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <span>

namespace cradle::tma {
namespace {

b2Body* static_body(b2World& world, Tag& tag) {
  b2BodyDef def;
  def.userData.pointer = reinterpret_cast<uintptr_t>(&tag);
  return world.CreateBody(&def);
}

// A two-sided ground or ceiling edge (friction 2.5, category 0x1, mask 0xFFFF).
b2Body* edge(b2World& world, Tag& tag, b2Vec2 a, b2Vec2 b) {
  b2Body* body = static_body(world, tag);
  b2EdgeShape shape;
  shape.SetTwoSided(a, b);
  b2FixtureDef fd;
  fd.shape = &shape;
  fd.friction = static_cast<float>(kFriction);
  fd.filter.categoryBits = kTerrainBits;
  fd.filter.maskBits = 0xFFFF;
  body->CreateFixture(&fd);
  return body;
}

b2Body* polygon(b2World& world, Tag& tag, b2BodyType type, std::span<const b2Vec2> points,
                double density, double friction, bool sensor) {
  b2BodyDef def;
  def.type = type;
  def.userData.pointer = reinterpret_cast<uintptr_t>(&tag);
  b2Body* body = world.CreateBody(&def);
  b2PolygonShape shape;
  shape.Set(points.data(), static_cast<int>(points.size()));
  b2FixtureDef fd;
  fd.shape = &shape;
  fd.density = static_cast<float>(density);
  fd.friction = static_cast<float>(friction);
  fd.isSensor = sensor;
  if (!sensor) fd.filter.maskBits = 0xFFFF;
  body->CreateFixture(&fd);
  return body;
}

b2Body* polygon(b2World& world, Tag& tag, b2BodyType type, std::initializer_list<b2Vec2> points,
                double density, double friction, bool sensor) {
  return polygon(world, tag, type, std::span<const b2Vec2>(points.begin(), points.size()), density,
                 friction, sensor);
}

}  // namespace

double normal(Rng& rng, double mean, double std) {
  // Box-Muller on two uniforms (1 - u keeps the log finite).
  const double u1 = 1.0 - rng.uniform(), u2 = rng.uniform();
  return mean + std * std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

void build_stump_tracks(b2World& world, const StumpTask& task, double startpad, Rng& rng,
                        TerrainTags& tags, Scene& scene) {
  scene = Scene{};
  const double spacing = std::max(0.01, task.obstacle_spacing);
  const double pad = startpad * kTerrainStep, end = kTerrainLength * kTerrainStep;
  // Recorded points: the pad, then each stump's left side at the ground height it stands on and its
  // right side at the height after the gap's roughness step (the reference also records a duplicate
  // point at the first stump: a zero-length edge, skipped here). The chain ends at the last
  // recorded x, which for spacing ~6 is before the finish line, as in the reference.
  std::vector<double>& xs = scene.xs;
  std::vector<double>& ys = scene.ground;
  xs = {0.0};
  ys = {kTerrainHeight};
  double y = kTerrainHeight, velocity = 0.0;
  for (double x = pad, width = kTerrainStep; x < end; x += spacing) {
    // Draws per stump: height, then width, then rotation (each only when its dimension is set).
    const double height = std::max(0.05, normal(rng, task.stump_height, 0.1)) * kTerrainStep;
    width = task.stump_width
                ? kTerrainStep *
                      std::max(0.05, normal(rng, (*task.stump_width)[0], (*task.stump_width)[1]))
                : kTerrainStep;
    // Corners relative to the bottom edge's middle, turned counter-clockwise by the drawn angle.
    const double half = width / 2, ax = x + half;
    const std::array<double, 4> dx{-half, half, half, -half}, dy{0, 0, height, height};
    double c = 1, s = 0;
    if (task.stump_rot) {
      const double angle = std::clamp(normal(rng, (*task.stump_rot)[0], (*task.stump_rot)[1]), 0.0,
                                      2 * std::numbers::pi);
      c = std::cos(angle);
      s = std::sin(angle);
    }
    std::array<b2Vec2, 4> poly;
    for (int k = 0; k < 4; ++k) {
      poly[k] = task.stump_rot ? at(ax + dx[k] * c - dy[k] * s, y + dx[k] * s + dy[k] * c)
                               : at(k == 0 || k == 3 ? x : x + width, y + dy[k]);
    }
    scene.bodies.push_back(polygon(world, tags.stump, b2_staticBody, poly, 0.0, kFriction, false));
    xs.push_back(x);
    ys.push_back(y);
    // The reference's loop ends where a stump reaches the end: no gap after the last one.
    x += width;
    if (x >= end) break;
    // The gap: the ground's vertical velocity relaxes towards TERRAIN_HEIGHT, plus roughness noise
    // (no draw at roughness 0, so the default stream stays the benchmark's).
    velocity = 0.8 * velocity + 0.01 * ((kTerrainHeight > y) - (kTerrainHeight < y));
    if (task.roughness > 0) velocity += rng.uniform(-task.roughness, task.roughness) / kScale;
    y += velocity;
    xs.push_back(x);
    ys.push_back(y);
  }
  for (size_t i = 0; i + 1 < xs.size(); ++i) {
    edge(world, tags.ground, at(xs[i], ys[i]), at(xs[i + 1], ys[i + 1]));
    scene.fills.push_back(
        Polygon{{at(xs[i], ys[i]), at(xs[i + 1], ys[i + 1]), at(xs[i + 1], 0), at(xs[i], 0)},
                Rgb{0.4f, 0.6f, 0.3f}});
  }
}

void build_parkour(b2World& world, const ParkourTask& task, const Cppn& cppn, double startpad,
                   bool movable_creepers, Rng& rng, TerrainTags& tags, Scene& scene,
                   double ceiling_offset, double ceiling_clip_offset) {
  scene = Scene{};
  const double scale = task.terrain_cppn_scale;
  scene.ceiling_offset = ceiling_offset / scale;
  const double clip_offset = ceiling_clip_offset / scale;
  scene.ground_limit = -1000.0 / scale;
  const double ceiling_limit = 1000.0 / scale;
  // CPPN rows: ground and ceiling divided by the scale and aligned to the start pad.
  std::vector<float> y;
  cppn.generate(task.input_vector, kTerrainLength, y);
  const double g0 = y[0] / scale, c0 = y[1] / scale;
  const int pad = static_cast<int>(std::ceil(startpad));
  const int n = kTerrainLength + pad;
  scene.xs.resize(n);
  scene.ground.resize(n);
  scene.ceiling.resize(n);
  for (int i = 0; i < n; ++i) {
    scene.xs[i] = i * kTerrainStep;
    if (i < pad) {
      scene.ground[i] = kTerrainHeight;
      scene.ceiling[i] = kTerrainHeight + scene.ceiling_offset;
    } else {
      const double g = y[2 * (i - pad)] / scale - g0 + kTerrainHeight;
      const double c = y[2 * (i - pad) + 1] / scale - c0 + kTerrainHeight + scene.ceiling_offset;
      scene.ground[i] = g;
      scene.ceiling[i] = std::max(c, g + clip_offset);  // at least clip_offset above the ground
    }
  }
  // Per edge: ground, ceiling, then a creeper when the spacing accumulator allows one.
  const bool creepers = task.creepers_width && task.creepers_height;
  const double spacing = std::max(0.01, task.creepers_spacing);
  double since_creeper = spacing;
  const auto& xs = scene.xs;
  for (int i = 0; i + 1 < n; ++i) {
    edge(world, tags.ground, at(xs[i], scene.ground[i]), at(xs[i + 1], scene.ground[i + 1]));
    scene.fills.push_back(
        Polygon{{at(xs[i], scene.ground[i]), at(xs[i + 1], scene.ground[i + 1]),
                 at(xs[i + 1], scene.ground_limit), at(xs[i], scene.ground_limit)},
                Rgb{0.4f, 0.6f, 0.3f}});
    b2Body* ceiling =
        edge(world, tags.grip, at(xs[i], scene.ceiling[i]), at(xs[i + 1], scene.ceiling[i + 1]));
    scene.fills.push_back(Polygon{{at(xs[i], scene.ceiling[i]), at(xs[i + 1], scene.ceiling[i + 1]),
                                   at(xs[i + 1], ceiling_limit), at(xs[i], ceiling_limit)},
                                  Rgb{0.5f, 0.5f, 0.5f}});
    if (!creepers) continue;
    if (since_creeper < spacing) {
      since_creeper += i > 0 ? xs[i] - xs[i - 1] : 0.0;
      continue;
    }
    const double height = std::max(0.2, normal(rng, *task.creepers_height, 0.1));
    const double width = std::max(0.2, *task.creepers_width);
    const int k = std::max(1, static_cast<int>(std::floor(width / kTerrainStep)));
    const double top = std::max(scene.ceiling[i], scene.ceiling[std::min(i + k, n - 1)]);
    if (movable_creepers) {
      // Dynamic 1-unit segments chained from the ceiling edge, joints limited to +-0.4 pi.
      b2Body* previous = ceiling;
      const int segments = static_cast<int>(std::ceil(height));
      for (int s = 0; s < segments; ++s) {
        const double hs =
            s == static_cast<int>(std::floor(height)) ? std::max(0.2, std::fmod(height, 1.0)) : 1.0;
        const double y_top = top - s;
        b2Body* part = polygon(world, tags.creeper, b2_dynamicBody,
                               {at(xs[i] + width, y_top - hs), at(xs[i] + width, y_top),
                                at(xs[i], y_top), at(xs[i], y_top - hs)},
                               5.0, 0.2, true);
        scene.bodies.push_back(part);
        b2RevoluteJointDef def;
        def.Initialize(previous, part, at(xs[i] + width / 2, y_top));
        def.enableLimit = true;
        def.lowerAngle = static_cast<float>(-0.4 * std::numbers::pi);
        def.upperAngle = static_cast<float>(0.4 * std::numbers::pi);
        world.CreateJoint(&def);
        previous = part;
      }
    } else {
      scene.bodies.push_back(polygon(world, tags.creeper, b2_staticBody,
                                     {at(xs[i], top), at(xs[i] + width, top),
                                      at(xs[i] + width, top - height), at(xs[i], top - height)},
                                     5.0, 0.2, true));
    }
    since_creeper = 0;
  }
  // Water from the ground limit up to water_level of the way to the highest ceiling point.
  const double level = std::max(0.01, task.water_level);
  const double top = *std::max_element(scene.ceiling.begin(), scene.ceiling.end());
  scene.water_y = scene.ground_limit + level * (top - scene.ground_limit);
  scene.water = polygon(world, tags.water, b2_staticBody,
                        {at(xs.front(), scene.ground_limit), at(xs.front(), scene.water_y),
                         at(xs.back(), scene.water_y), at(xs.back(), scene.ground_limit)},
                        kWaterDensity, 0.2, true);
  scene.bodies.push_back(scene.water);
}

void make_clouds(Rng& rng, Scene& scene) {
  for (int c = 0; c < kTerrainLength / 20; ++c) {
    const double x = rng.uniform(0, kTerrainLength) * kTerrainStep;
    const double y = kViewportH / kScale * 3 / 4;
    Polygon cloud{.color = {1, 1, 1}};
    for (int a = 0; a < 5; ++a) {
      const double px =
          x + 15 * kTerrainStep * std::sin(3.14 * 2 * a / 5) + rng.uniform(0, 5 * kTerrainStep);
      const double py =
          y + 5 * kTerrainStep * std::cos(3.14 * 2 * a / 5) + rng.uniform(0, 5 * kTerrainStep);
      cloud.points.push_back(at(px, py));
    }
    scene.clouds.push_back(std::move(cloud));
  }
}

}  // namespace cradle::tma

// Terrain of both environments: Stump Tracks (flat ground with stumps) and Parkour (CPPN ground and
// ceiling, creepers, water). Every terrain body is static at the origin with world-coordinate
// vertices; `Scene` keeps what the renderer and the tests read back.
#pragma once

#include <box2d/box2d.h>

#include <array>
#include <optional>
#include <vector>

#include "core/rng.h"
#include "tma/cppn.h"
#include "tma/physics.h"

namespace cradle::tma {

// Stump Tracks task: stump heights ~ N(stump_height, 0.1) in TERRAIN_STEP units (floored at 0.05),
// `obstacle_spacing` world units between stumps (floored at 0.01). Optional dimensions (unused by
// the benchmark): stump width = TERRAIN_STEP * max(0.05, N(mean, std)); stump rotation (radians,
// counter-clockwise about the bottom edge's middle) = clip(N(mean, std), 0, 2 pi); roughness r adds
// uniform(-r, r) / 30 to the ground's vertical velocity at every gap.
struct StumpTask {
  double stump_height = 0.0;
  double obstacle_spacing = 8.0;
  std::optional<std::array<double, 2>> stump_width, stump_rot;  // (mean, std)
  double roughness = 0.0;
};

// Parkour task (the 8-D task vector of the benchmark).
struct ParkourTask {
  std::vector<double> input_vector{0, 0, 0};  // the CPPN's input dimension (3) values
  double water_level = 0.0;  // floored at 0.01
  std::optional<double> creepers_width, creepers_height;
  double creepers_spacing = 0.1;  // floored at 0.01
  double terrain_cppn_scale = 10.0;
};

struct Polygon {
  std::vector<b2Vec2> points;
  Rgb color;
};

// The user-data records of terrain bodies, owned by the environment.
struct TerrainTags {
  Tag ground{.type = ObjectType::kTerrain};
  Tag stump{.type = ObjectType::kTerrain, .color1 = {1, 1, 1}, .color2 = {0.6f, 0.6f, 0.6f}};
  Tag grip{.type = ObjectType::kGripTerrain};
  Tag water{.type = ObjectType::kWater,
            .color1 = {0.465f, 0.676f, 0.898f},
            .color2 = {0.465f, 0.676f, 0.898f}};
  Tag creeper{.type = ObjectType::kCreeper,
              .color1 = {0.437f, 0.504f, 0.375f},
              .color2 = {0.537f, 0.604f, 0.475f}};
};

struct Scene {
  std::vector<Polygon> fills;  // ground (and ceiling) fills, drawn behind the agent
  std::vector<Polygon> clouds;
  std::vector<b2Body*> bodies;              // stumps, creepers and water, drawn from their fixtures
  std::vector<double> xs, ground, ceiling;  // terrain points (Parkour ceiling; empty otherwise)
  b2Body* water = nullptr;
  double water_y = -1e9;      // no water in Stump Tracks
  double ceiling_offset = 0;  // Parkour: ceiling_offset / scale (200 / scale by default)
  double ground_limit = 0;    // Parkour: -1000 / scale
};

double normal(Rng& rng, double mean, double std);

void build_stump_tracks(b2World& world, const StumpTask& task, double startpad, Rng& rng,
                        TerrainTags& tags, Scene& scene);
// The ceiling starts `ceiling_offset` above the start pad and stays at least `ceiling_clip_offset`
// above it (both in CPPN units, divided by the task's terrain_cppn_scale).
void build_parkour(b2World& world, const ParkourTask& task, const Cppn& cppn, double startpad,
                   bool movable_creepers, Rng& rng, TerrainTags& tags, Scene& scene,
                   double ceiling_offset = 200, double ceiling_clip_offset = 0);
// Ten five-point clouds (rendering only), 110 draws as in the reference.
void make_clouds(Rng& rng, Scene& scene);

}  // namespace cradle::tma

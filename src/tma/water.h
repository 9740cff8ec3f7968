// Water forces (tma_sami.md §3.2, tma_bodies.md §5.4): buoyancy, drag and lift on the submerged
// part of each body polygon touching the water, and the "push" of moving joints that makes the
// fish swim. Forces are applied after the world step, so they act during the next one.
#pragma once

#include <box2d/box2d.h>

#include <utility>
#include <vector>

namespace cradle::tma {

struct WaterParams {
  double drag_mod = 0.25, lift_mod = 0.25, push_mod = 0.05;
  double max_drag = 2000, max_lift = 500, max_push = 20;  // max_push: the env's water_clip
};

void apply_water_forces(const std::vector<std::pair<b2Fixture*, b2Fixture*>>& pairs,
                        const b2Vec2& gravity, const WaterParams& params);

// The polygon of `subject` inside the convex counter-clockwise `clip` (Sutherland-Hodgman; points
// on a clip edge count as outside). Writes at most `capacity` points; returns the count.
int clip_polygon(const b2Vec2* subject, int n_subject, const b2Vec2* clip, int n_clip, b2Vec2* out,
                 int capacity);
// Area and centroid of a polygon by a triangle fan about the origin. An area of at most
// b2_epsilon reads 0 and leaves the centroid unnormalised (the reference's rule).
double polygon_area_centroid(const b2Vec2* poly, int n, b2Vec2* centroid);

}  // namespace cradle::tma

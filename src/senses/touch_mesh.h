// Touch sensor points on MuJoCo geom primitives (mimo_core.md §4.4): where the sensors of one geom
// lie at a target spacing, and whether a point lies inside a primitive (overlap removal).
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <vector>

namespace cradle::senses {

using Point3 = std::array<double, 3>;

// A geom's shape as the touch generator sees it: MuJoCo type and size; rbound stands in for meshes.
struct Shape {
  mjtGeom type = mjGEOM_SPHERE;
  std::array<double, 3> size{0, 0, 0};
  double rbound = 0;
};

// Surface points of `shape` in its own frame at target spacing `resolution`, duplicates merged,
// in a fixed order. A primitive too small for the resolution gives one point at its centre
// (see single_point); planes and height fields give none.
std::vector<Point3> shape_points(const Shape& shape, double resolution);

// True when shape_points would return only the centre point (such geoms never hide others).
bool single_point(const Shape& shape, double resolution);

// True when p (shape frame) lies inside the primitive by more than `tolerance` metres.
// Meshes count as their bounding sphere; planes and height fields contain nothing.
bool inside_shape(const Shape& shape, const Point3& p, double tolerance);

}  // namespace cradle::senses

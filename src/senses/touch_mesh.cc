#include "senses/touch_mesh.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace cradle::senses {
namespace {

constexpr double kPi = std::numbers::pi;
// Points closer than this are one vertex (the reference merges mesh vertices at ~1e-8).
constexpr double kMergeTolerance = 1e-8;

// The i-th of n evenly spaced values from lo to hi inclusive (numpy linspace; n == 1 gives lo).
double lerp_at(double lo, double hi, int i, int n) {
  if (n <= 1) return lo;
  if (i == n - 1) return hi;
  return lo + (hi - lo) / (n - 1) * i;
}

int ceil_int(double x) { return static_cast<int>(std::ceil(x)); }

// Python's round(): nearest integer, ties to even (the default floating-point rounding mode).
int round_even(double x) { return static_cast<int>(std::nearbyint(x)); }

// n points on the circle of radius rho at height z, starting on +x.
void add_ring(double rho, double z, int n, std::vector<Point3>& out) {
  for (int j = 0; j < n; ++j) {
    const double phi = 2 * kPi * j / n;
    out.push_back({rho * std::cos(phi), rho * std::sin(phi), z});
  }
}

// Drops every point within kMergeTolerance of an earlier one, keeping first occurrences in order.
std::vector<Point3> merge_duplicates(const std::vector<Point3>& points) {
  const int n = static_cast<int>(points.size());
  std::vector<int> by_x(n);
  for (int i = 0; i < n; ++i) by_x[i] = i;
  std::sort(by_x.begin(), by_x.end(), [&](int a, int b) {
    return points[a][0] < points[b][0] || (points[a][0] == points[b][0] && a < b);
  });
  // Sweep in x order; a duplicate pair is at most the tolerance apart in x.
  std::vector<bool> dropped(n, false);
  for (int a = 0; a < n; ++a) {
    const Point3& p = points[by_x[a]];
    for (int b = a + 1; b < n && points[by_x[b]][0] - p[0] < kMergeTolerance; ++b) {
      const Point3& q = points[by_x[b]];
      const double dy = q[1] - p[1], dz = q[2] - p[2], dx = q[0] - p[0];
      if (dx * dx + dy * dy + dz * dz < kMergeTolerance * kMergeTolerance) {
        dropped[std::max(by_x[a], by_x[b])] = true;
      }
    }
  }
  std::vector<Point3> out;
  out.reserve(n);
  for (int i = 0; i < n; ++i) {
    if (!dropped[i]) out.push_back(points[i]);
  }
  return out;
}

// Box faces: the surface nodes of a grid with at least 2 nodes per axis.
void box_points(const std::array<double, 3>& h, double r, std::vector<Point3>& out) {
  std::array<int, 3> n;
  for (int k = 0; k < 3; ++k) n[k] = std::max(2, ceil_int(2 * h[k] / r));
  for (int i = 0; i < n[0]; ++i) {
    for (int j = 0; j < n[1]; ++j) {
      for (int k = 0; k < n[2]; ++k) {
        const bool face =
            i == 0 || i == n[0] - 1 || j == 0 || j == n[1] - 1 || k == 0 || k == n[2] - 1;
        if (face) {
          out.push_back({lerp_at(-h[0], h[0], i, n[0]), lerp_at(-h[1], h[1], j, n[1]),
                         lerp_at(-h[2], h[2], k, n[2])});
        }
      }
    }
  }
}

// Sphere: latitude rings at mid-band angles, each spaced ~r around.
void sphere_points(double radius, double r, std::vector<Point3>& out) {
  const int rings = ceil_int(kPi * radius / r);
  for (int i = 0; i < rings; ++i) {
    const double theta = (i + 0.5) * kPi / rings;
    const int n = round_even(2 * kPi * radius * std::sin(theta) / r);
    add_ring(radius * std::sin(theta), radius * std::cos(theta), n, out);
  }
}

// Side of a capsule or cylinder: `rings` evenly spaced rings of n points from z = -h to +h.
void side_points(double radius, double h, int rings, int n, std::vector<Point3>& out) {
  for (int i = 0; i < rings; ++i) add_ring(radius, lerp_at(-h, h, i, rings), n, out);
}

// Capsule: side rings plus two hemispherical caps of latitude rings (pole point where too few).
void capsule_points(double radius, double h, double r, std::vector<Point3>& out) {
  const int around = ceil_int(2 * kPi * radius / r);
  side_points(radius, h, ceil_int(2 * h / r) + 1, around, out);
  const int bands = ceil_int(kPi * radius / (2 * r));
  for (double sign : {1.0, -1.0}) {
    for (int i = 0; i <= bands; ++i) {
      const double theta = i * kPi / (2 * bands);
      const int n = ceil_int(2 * kPi * radius * std::sin(theta) / r);
      if (n < 2) {
        out.push_back({0, 0, sign * (h + radius)});
      } else {
        add_ring(radius * std::sin(theta), sign * (radius * std::cos(theta) + h), n, out);
      }
    }
  }
}

// Cylinder: side rings plus flat caps of concentric rings (centre point at radius 0).
void cylinder_points(double radius, double h, double r, std::vector<Point3>& out) {
  side_points(radius, h, ceil_int(2 * h / r) + 1, ceil_int(2 * kPi * radius / r), out);
  const int radii = round_even(radius / r) + 1;
  for (double sign : {1.0, -1.0}) {
    for (int i = 0; i < radii; ++i) {
      const double rho = lerp_at(0, radius, i, radii);
      if (rho < 1e-12) {
        out.push_back({0, 0, sign * h});
      } else {
        add_ring(rho, sign * h, ceil_int(2 * kPi * rho / r), out);
      }
    }
  }
}

// Ellipsoid: the sphere scheme at the largest semi-axis, each point moved along its ray onto the
// ellipsoid surface.
void ellipsoid_points(const std::array<double, 3>& a, double r, std::vector<Point3>& out) {
  const size_t first = out.size();
  sphere_points(std::max({a[0], a[1], a[2]}), r, out);
  for (size_t i = first; i < out.size(); ++i) {
    Point3& p = out[i];
    double q = 0;
    for (int k = 0; k < 3; ++k) q += (p[k] / a[k]) * (p[k] / a[k]);
    const double t = 1 / std::sqrt(q);
    for (double& c : p) c *= t;
  }
}

}  // namespace

bool single_point(const Shape& shape, double r) {
  const auto& s = shape.size;
  switch (shape.type) {
    case mjGEOM_BOX:
      return 0.75 * r > std::max({s[0], s[1], s[2]});
    case mjGEOM_SPHERE:
      return r > s[0];
    case mjGEOM_CAPSULE:
      return ceil_int(2 * kPi * s[0] / r) < 3;
    case mjGEOM_CYLINDER:
      return ceil_int(2 * kPi * s[0] / r) < 3 || ceil_int(2 * s[1] / r) < 2 ||
             round_even(s[0] / r) + 1 == 1;
    case mjGEOM_ELLIPSOID:
      return r > std::max({s[0], s[1], s[2]});
    case mjGEOM_MESH:
      return r > shape.rbound;
    default:
      return false;
  }
}

std::vector<Point3> shape_points(const Shape& shape, double r) {
  const auto& s = shape.size;
  std::vector<Point3> out;
  if (shape.type == mjGEOM_PLANE || shape.type == mjGEOM_HFIELD) return out;
  if (single_point(shape, r)) return {Point3{0, 0, 0}};
  switch (shape.type) {
    case mjGEOM_BOX:
      box_points(s, r, out);
      break;
    case mjGEOM_SPHERE:
      sphere_points(s[0], r, out);
      break;
    case mjGEOM_CAPSULE:
      capsule_points(s[0], s[1], r, out);
      break;
    case mjGEOM_CYLINDER:
      cylinder_points(s[0], s[1], r, out);
      break;
    case mjGEOM_ELLIPSOID:
      ellipsoid_points(s, r, out);
      break;
    case mjGEOM_MESH:
      sphere_points(shape.rbound, r, out);
      break;
    default:
      break;
  }
  if (out.empty()) out.push_back({0, 0, 0});
  return merge_duplicates(out);
}

bool inside_shape(const Shape& shape, const Point3& p, double tol) {
  const auto& s = shape.size;
  const double radial = std::hypot(p[0], p[1]);
  switch (shape.type) {
    case mjGEOM_SPHERE:
      return std::hypot(radial, p[2]) < s[0] - tol;
    case mjGEOM_MESH:
      return std::hypot(radial, p[2]) < shape.rbound - tol;
    case mjGEOM_CAPSULE: {
      const double dz = std::max(0.0, std::abs(p[2]) - s[1]);
      return std::hypot(radial, dz) < s[0] - tol;
    }
    case mjGEOM_CYLINDER:
      return radial < s[0] - tol && std::abs(p[2]) < s[1] - tol;
    case mjGEOM_BOX:
      return std::abs(p[0]) < s[0] - tol && std::abs(p[1]) < s[1] - tol &&
             std::abs(p[2]) < s[2] - tol;
    case mjGEOM_ELLIPSOID: {
      // Shrink the semi-axes by the tolerance; exact enough for a yes/no inside test.
      double q = 0;
      for (int k = 0; k < 3; ++k) {
        const double a = s[k] - tol;
        if (a <= 0) return false;
        q += (p[k] / a) * (p[k] / a);
      }
      return q < 1;
    }
    default:
      return false;
  }
}

}  // namespace cradle::senses

#include "tma/water.h"

#include <algorithm>
#include <cmath>

#include "tma/physics.h"

namespace cradle::tma {
namespace {

constexpr int kMaxPoints = 32;

// The clipping runs in doubles on the float vertices, as the reference's Python does: the water
// polygon spans the whole terrain (x up to ~100, y down to -100), so in floats the cross products
// of its corners would lose the body's scale to cancellation.
bool inside(const b2Vec2& c1, const b2Vec2& c2, const b2Vec2& p) {
  return (double{c2.x} - c1.x) * (double{p.y} - c1.y) >
         (double{c2.y} - c1.y) * (double{p.x} - c1.x);
}

b2Vec2 intersection(const b2Vec2& c1, const b2Vec2& c2, const b2Vec2& s, const b2Vec2& e) {
  // The edge directions are stored as Box2D vectors (floats) in the reference; the rest is double.
  const b2Vec2 dc = c1 - c2, dp = s - e;
  const double n1 = double{c1.x} * c2.y - double{c1.y} * c2.x;
  const double n2 = double{s.x} * e.y - double{s.y} * e.x;
  const double n3 = 1.0 / (double{dc.x} * dp.y - double{dc.y} * dp.x);
  return at((n1 * dp.x - n2 * dc.x) * n3, (n1 * dp.y - n2 * dc.y) * n3);
}

// World-space vertices of a polygon fixture (counter-clockwise, as Box2D stores them).
int world_polygon(const b2Fixture* f, b2Vec2* out) {
  const auto* poly = static_cast<const b2PolygonShape*>(f->GetShape());
  const b2Transform& xf = f->GetBody()->GetTransform();
  for (int k = 0; k < poly->m_count; ++k) out[k] = b2Mul(xf, poly->m_vertices[k]);
  return poly->m_count;
}

}  // namespace

int clip_polygon(const b2Vec2* subject, int n_subject, const b2Vec2* clip, int n_clip, b2Vec2* out,
                 int capacity) {
  b2Vec2 buf[kMaxPoints];
  int n = std::min(n_subject, kMaxPoints);
  std::copy(subject, subject + n, out);
  b2Vec2 c1 = clip[n_clip - 1];
  for (int j = 0; j < n_clip && n > 0; ++j) {
    const b2Vec2 c2 = clip[j];
    std::copy(out, out + n, buf);
    const int n_in = n;
    n = 0;
    b2Vec2 s = buf[n_in - 1];
    for (int i = 0; i < n_in; ++i) {
      const b2Vec2 e = buf[i];
      if (inside(c1, c2, e)) {
        if (!inside(c1, c2, s) && n < capacity) out[n++] = intersection(c1, c2, s, e);
        if (n < capacity) out[n++] = e;
      } else if (inside(c1, c2, s) && n < capacity) {
        out[n++] = intersection(c1, c2, s, e);
      }
      s = e;
    }
    c1 = c2;
  }
  return n;
}

double polygon_area_centroid(const b2Vec2* poly, int n, b2Vec2* centroid) {
  // Float cross products and vector sums, the area summed in double (the reference's mix).
  double area = 0;
  b2Vec2 c(0, 0);
  for (int i = 0; i < n; ++i) {
    const b2Vec2& p1 = poly[i];
    const b2Vec2& p2 = poly[(i + 1) % n];
    const double a = 0.5 * b2Cross(p1, p2);
    area += a;
    c += static_cast<float>(a * (1.0 / 3.0)) * (p1 + p2);
  }
  if (area > b2_epsilon) {
    c *= static_cast<float>(1.0 / area);
  } else {
    area = 0;
  }
  *centroid = c;
  return area;
}

void apply_water_forces(const std::vector<std::pair<b2Fixture*, b2Fixture*>>& pairs,
                        const b2Vec2& gravity, const WaterParams& params) {
  b2Vec2 water_poly[b2_maxPolygonVertices], body_poly[b2_maxPolygonVertices], wet[kMaxPoints];
  for (const auto& [water, fixture] : pairs) {
    if (fixture->GetShape()->GetType() != b2Shape::e_polygon) continue;
    b2Body* body = fixture->GetBody();
    const b2Body* water_body = water->GetBody();
    const float density = water->GetDensity();
    const int nw = world_polygon(water, water_poly);
    const int nb = world_polygon(fixture, body_poly);
    const int n = clip_polygon(water_poly, nw, body_poly, nb, wet, kMaxPoints);
    if (n == 0) continue;
    b2Vec2 centroid;
    const double area = polygon_area_centroid(wet, n, &centroid);

    // Buoyancy: the weight of the displaced water, at the submerged centroid. A sliver (area at
    // most b2_epsilon) displaces nothing but still gets drag, lift and push below.
    body->ApplyForce(static_cast<float>(density * area) * -gravity, centroid, true);

    for (int i = 0; i < n; ++i) {
      const b2Vec2 v0 = wet[i], v1 = wet[(i + 1) % n];
      const b2Vec2 mid = 0.5f * (v0 + v1);
      b2Vec2 vel = body->GetLinearVelocityFromWorldPoint(mid) -
                   water_body->GetLinearVelocityFromWorldPoint(mid);
      const float speed = vel.Normalize();
      b2Vec2 edge = v1 - v0;
      const float length = edge.Normalize();
      const b2Vec2 normal = b2Cross(-1.0f, edge);
      // Drag and lift on edges facing the flow.
      const float drag_dot = b2Dot(normal, vel);
      if (drag_dot >= 0) {
        const float drag = std::min(
            static_cast<float>(drag_dot * params.drag_mod * length * density * speed * speed),
            static_cast<float>(params.max_drag));
        body->ApplyForce(-drag * vel, mid, true);
        const float lift_dot = b2Dot(edge, vel);
        const float lift =
            std::min(static_cast<float>(double{drag_dot} * lift_dot * params.lift_mod * length *
                                        density * speed * speed),
                     static_cast<float>(params.max_lift));
        body->ApplyForce(lift * b2Cross(1.0f, vel), mid, true);
      }
      // Push: joints whose bodyB is this body, strictly inside their limits, shove the water. A
      // joint held at a limit rests past it (box2d23_limits), so a pinned part does not push.
      for (b2JointEdge* je = body->GetJointList(); je; je = je->next) {
        b2Joint* j = je->joint;
        if (j->GetBodyB() != body || j->GetType() != e_revoluteJoint) continue;
        auto* rj = static_cast<b2RevoluteJoint*>(j);
        const float angle = rj->GetJointAngle();
        if (!(rj->GetLowerLimit() < angle && angle < rj->GetUpperLimit())) continue;
        const float torque = rj->GetMotorTorque(60.0f);
        const double momentum = double{body->GetInertia()} * body->GetAngularVelocity();
        const b2Vec2 lever = body->GetWorldCenter() - rj->GetAnchorB();
        const b2Vec2 at_center = b2Cross(lever, -torque);
        const float push_dot = b2Dot(normal, at_center);
        if (push_dot <= 0) continue;
        const double v = torque + momentum;
        const float magnitude =
            static_cast<float>(push_dot * params.push_mod * length * density * v * v);
        const float clip = static_cast<float>(params.max_push);
        const b2Vec2 force(std::clamp(-magnitude * at_center.x, -clip, clip),
                           std::clamp(-magnitude * at_center.y, -clip, clip));
        body->ApplyForce(force, rj->GetAnchorB(), true);
      }
    }
  }
}

}  // namespace cradle::tma

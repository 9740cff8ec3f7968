#include "tma/render.h"

#include <cairo.h>

#include <algorithm>
#include <memory>
#include <string>

#include "core/error.h"
#include "tma/tma_env.h"

namespace cradle::tma {
namespace {

struct View {
  cairo_t* cr;
  double sx, sy, k, h;  // scroll (world), pixels per unit, image height
  void move(const b2Vec2& p) const { cairo_move_to(cr, (p.x - sx) * k, h - (p.y - sy) * k); }
  void line(const b2Vec2& p) const { cairo_line_to(cr, (p.x - sx) * k, h - (p.y - sy) * k); }
};

void color(cairo_t* cr, const Rgb& c) { cairo_set_source_rgb(cr, c.r, c.g, c.b); }

void path(const View& v, const b2Vec2* p, int n) {
  v.move(p[0]);
  for (int i = 1; i < n; ++i) v.line(p[i]);
  cairo_close_path(v.cr);
}

// Fills and outlines every fixture of a body (polygons and circles).
void draw_body(const View& v, const b2Body* body, Rgb c1, Rgb c2) {
  const b2Transform& xf = body->GetTransform();
  for (const b2Fixture* f = body->GetFixtureList(); f; f = f->GetNext()) {
    const b2Shape* shape = f->GetShape();
    if (shape->GetType() == b2Shape::e_polygon) {
      const auto* poly = static_cast<const b2PolygonShape*>(shape);
      b2Vec2 p[b2_maxPolygonVertices];
      for (int i = 0; i < poly->m_count; ++i) p[i] = b2Mul(xf, poly->m_vertices[i]);
      path(v, p, poly->m_count);
    } else if (shape->GetType() == b2Shape::e_circle) {
      const auto* circle = static_cast<const b2CircleShape*>(shape);
      const b2Vec2 c = b2Mul(xf, circle->m_p);
      cairo_new_sub_path(v.cr);
      cairo_arc(v.cr, (c.x - v.sx) * v.k, v.h - (c.y - v.sy) * v.k, circle->m_radius * v.k, 0,
                2 * 3.14159265358979);
    } else {
      continue;
    }
    color(v.cr, c1);
    cairo_fill_preserve(v.cr);
    color(v.cr, c2);
    cairo_set_line_width(v.cr, 2.0 * v.k / kScale);
    cairo_stroke(v.cr);
  }
}

}  // namespace

void render(const TmaEnv& env, int width, int height, bool draw_lidars,
            std::vector<std::uint8_t>& rgb) {
  if (width < 16 || height < 16 || width > 4096 || height > 4096) {
    throw UserError("render size " + std::to_string(width) + "x" + std::to_string(height) +
                    " (expected 16..4096 pixels each way)");
  }
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surface(
      cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height), cairo_surface_destroy);
  std::unique_ptr<cairo_t, decltype(&cairo_destroy)> context(cairo_create(surface.get()),
                                                             cairo_destroy);
  cairo_t* cr = context.get();
  const bool parkour = env.options().env == EnvId::kParkour;
  const Agent& agent = env.agent();
  const b2Vec2 pos = agent.head->GetPosition();
  const double view_w = kViewportW / kScale;
  View v{.cr = cr, .sx = pos.x - view_w / 5, .sy = 0, .k = width / view_w, .h = double(height)};
  if (parkour) v.sy = pos.y - kViewportH / kScale / 5 - kTerrainHeight + 1 / kScale;
  const Scene& scene = env.scene();

  // Sky and clouds (clouds scroll at half speed).
  cairo_set_source_rgb(cr, 0.9, 0.9, 1.0);
  cairo_paint(cr);
  for (const Polygon& cloud : scene.clouds) {
    std::vector<b2Vec2> p = cloud.points;
    for (b2Vec2& q : p) q.x += static_cast<float>(v.sx / 2);
    path(v, p.data(), static_cast<int>(p.size()));
    color(cr, cloud.color);
    cairo_fill(cr);
  }
  // Ground (and ceiling) fills, only those in view; adjacent pieces share edges, so no
  // antialiasing (it would leave seams).
  auto fills = [&] {
    cairo_set_antialias(cr, CAIRO_ANTIALIAS_NONE);
    for (const Polygon& poly : scene.fills) {
      if (poly.points[1].x < v.sx || poly.points[0].x > v.sx + view_w) continue;
      path(v, poly.points.data(), static_cast<int>(poly.points.size()));
      color(cr, poly.color);
      cairo_fill(cr);
    }
    cairo_set_antialias(cr, CAIRO_ANTIALIAS_DEFAULT);
  };
  // Stump Tracks draws the ground behind everything; Parkour in front (it hides the water below).
  if (!parkour) fills();
  // Water, stumps and creepers.
  for (const b2Body* body : scene.bodies) {
    const Tag* tag = tag_of(body);
    draw_body(v, body, tag->color1, tag->color2);
  }
  // The agent: the head reddens with its drowning / drying counter; grasping sensors turn yellow.
  double ratio = 0;
  if (parkour && agent.kind == BodyKind::kSwimmer) ratio = env.steps_outside_water() / 600.0;
  if (parkour && (agent.kind == BodyKind::kWalker || agent.kind == BodyKind::kClimber)) {
    ratio = env.steps_under_water() / 600.0;
  }
  ratio = std::min(ratio, 1.0);
  for (const b2Body* body : agent.parts) {
    const Tag* tag = tag_of(body);
    Rgb c1 = tag->color1;
    if (body == agent.head) {
      c1 = Rgb{static_cast<float>(c1.r + ratio * (1 - c1.r)),
               static_cast<float>(c1.g * (1 - ratio)), static_cast<float>(c1.b * (1 - ratio))};
    }
    draw_body(v, body, c1, tag->color2);
  }
  for (const Sensor& s : agent.sensors) {
    const Rgb c = s.tag->has_joint ? Rgb{1, 1, 0} : s.tag->color1;
    draw_body(v, s.body, c, c);
  }
  if (parkour) fills();
  // Lidar rays.
  if (draw_lidars) {
    cairo_set_source_rgb(cr, 1, 0, 0);
    cairo_set_line_width(cr, 1.0);
    for (const LidarReading& r : env.lidars()) {
      v.move(r.p1);
      v.line(r.p2);
      cairo_stroke(cr);
    }
  }
  // Start flag.
  const double fx = kTerrainStep * 3, fy1 = kTerrainHeight, fy2 = fy1 + 50 / kScale;
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_line_width(cr, 2.0 * v.k / kScale);
  v.move(at(fx, fy1));
  v.line(at(fx, fy2));
  cairo_stroke(cr);
  const b2Vec2 flag[3] = {at(fx, fy2), at(fx, fy2 - 10 / kScale),
                          at(fx + 25 / kScale, fy2 - 5 / kScale)};
  path(v, flag, 3);
  cairo_set_source_rgb(cr, 0.9, 0.2, 0);
  cairo_fill_preserve(cr);
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_stroke(cr);

  // Cairo's RGB24 is 0x00RRGGBB per 32-bit pixel; copy out as packed RGB.
  cairo_surface_flush(surface.get());
  const unsigned char* data = cairo_image_surface_get_data(surface.get());
  const int stride = cairo_image_surface_get_stride(surface.get());
  rgb.resize(static_cast<size_t>(width) * height * 3);
  for (int y = 0; y < height; ++y) {
    const auto* row =
        reinterpret_cast<const std::uint32_t*>(data + static_cast<size_t>(y) * stride);
    std::uint8_t* out = rgb.data() + static_cast<size_t>(y) * width * 3;
    for (int x = 0; x < width; ++x) {
      out[3 * x] = static_cast<std::uint8_t>(row[x] >> 16);
      out[3 * x + 1] = static_cast<std::uint8_t>(row[x] >> 8);
      out[3 * x + 2] = static_cast<std::uint8_t>(row[x]);
    }
  }
}

}  // namespace cradle::tma

#include "eval/plot.h"

#include <stb_easy_font.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <numbers>
#include <string_view>
#include <system_error>

#include "core/error.h"

namespace cradle::eval {
namespace {

constexpr Rgb kText{34, 34, 34};
constexpr Rgb kTickText{70, 70, 70};
constexpr Rgb kFrame{120, 120, 120};
constexpr Rgb kGrid{232, 232, 232};
constexpr Rgb kRefLine{105, 105, 105};
constexpr Rgb kMuted{150, 150, 150};
constexpr Rgb kLegendBorder{205, 205, 205};
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kMinWidth = 160;
constexpr int kMinHeight = 100;

struct Point {
  double x = 0;
  double y = 0;
};

// Axis-aligned rectangle, x0 <= x1 and y0 <= y1, in pixels (pixel (i, j) spans [i, i+1)).
struct Box {
  double x0 = 0;
  double y0 = 0;
  double x1 = 0;
  double y1 = 0;
  double width() const { return x1 - x0; }
  double height() const { return y1 - y0; }
};

// Closed interval of data values shown along one axis.
struct Range {
  double lo = 0;
  double hi = 1;
};

// An RGB image with alpha-blended, antialiased drawing.
class Canvas {
 public:
  Canvas(int width, int height)
      : image_{width, height, std::vector<std::uint8_t>(3 * width * height, 255)} {}

  int width() const { return image_.width; }
  int height() const { return image_.height; }

  // Blends colour c with opacity a into pixel (x, y); pixels outside are ignored.
  void blend(int x, int y, Rgb c, double a) {
    if (x < 0 || y < 0 || x >= image_.width || y >= image_.height || !(a > 0)) return;
    a = std::min(a, 1.0);
    std::uint8_t* p = &image_.rgb[3 * (static_cast<std::size_t>(y) * image_.width + x)];
    const auto mix = [a](std::uint8_t from, std::uint8_t to) {
      return static_cast<std::uint8_t>(std::lround(from + (to - from) * a));
    };
    p[0] = mix(p[0], c.r);
    p[1] = mix(p[1], c.g);
    p[2] = mix(p[2], c.b);
  }

  // Fills a rectangle; edge pixels get the fraction of their area it covers.
  void fill_rect(Box b, Rgb c, double alpha = 1) {
    b.x0 = std::max(b.x0, 0.0);
    b.y0 = std::max(b.y0, 0.0);
    b.x1 = std::min(b.x1, static_cast<double>(image_.width));
    b.y1 = std::min(b.y1, static_cast<double>(image_.height));
    if (!(b.x0 < b.x1) || !(b.y0 < b.y1)) return;
    for (int y = static_cast<int>(b.y0); y < std::ceil(b.y1); ++y) {
      const double cy = std::min(b.y1, y + 1.0) - std::max(b.y0, static_cast<double>(y));
      for (int x = static_cast<int>(b.x0); x < std::ceil(b.x1); ++x) {
        const double cx = std::min(b.x1, x + 1.0) - std::max(b.x0, static_cast<double>(x));
        blend(x, y, c, alpha * cx * cy);
      }
    }
  }

  // Fills a convex quadrilateral (corners in order) with 4x4 supersampling.
  void fill_quad(const std::array<Point, 4>& q, Rgb c) {
    double x0 = q[0].x, x1 = q[0].x, y0 = q[0].y, y1 = q[0].y;
    for (const Point& p : q) {
      x0 = std::min(x0, p.x);
      x1 = std::max(x1, p.x);
      y0 = std::min(y0, p.y);
      y1 = std::max(y1, p.y);
    }
    // Sign of twice the signed area: the side every inside sample lies on for each edge.
    double area = 0;
    for (int i = 0; i < 4; ++i) {
      area += q[i].x * q[(i + 1) % 4].y - q[(i + 1) % 4].x * q[i].y;
    }
    const auto inside = [&](double x, double y) {
      for (int i = 0; i < 4; ++i) {
        const Point& a = q[i];
        const Point& b = q[(i + 1) % 4];
        if (((b.x - a.x) * (y - a.y) - (b.y - a.y) * (x - a.x)) * area < 0) return false;
      }
      return true;
    };
    const int ix0 = std::max(0, static_cast<int>(std::floor(x0)));
    const int iy0 = std::max(0, static_cast<int>(std::floor(y0)));
    const int ix1 = std::min(image_.width, static_cast<int>(std::ceil(x1)));
    const int iy1 = std::min(image_.height, static_cast<int>(std::ceil(y1)));
    for (int y = iy0; y < iy1; ++y) {
      for (int x = ix0; x < ix1; ++x) {
        int hits = 0;
        for (int sy = 0; sy < 4; ++sy) {
          for (int sx = 0; sx < 4; ++sx) hits += inside(x + (sx + 0.5) / 4, y + (sy + 0.5) / 4);
        }
        blend(x, y, c, hits / 16.0);
      }
    }
  }

  // Fills a disc with an antialiased rim.
  void fill_disc(Point center, double radius, Rgb c) {
    for (int y = static_cast<int>(std::floor(center.y - radius - 1));
         y <= static_cast<int>(std::ceil(center.y + radius + 1)); ++y) {
      for (int x = static_cast<int>(std::floor(center.x - radius - 1));
           x <= static_cast<int>(std::ceil(center.x + radius + 1)); ++x) {
        const double d = std::hypot(x + 0.5 - center.x, y + 0.5 - center.y);
        blend(x, y, c, std::clamp(radius + 0.5 - d, 0.0, 1.0));
      }
    }
  }

  model::Image release() && { return std::move(image_); }

 private:
  model::Image image_;
};

// Clips segment pq to a box (Liang-Barsky); false when nothing is left.
bool clip_segment(Point& p, Point& q, const Box& box) {
  double t0 = 0;
  double t1 = 1;
  const double dx = q.x - p.x;
  const double dy = q.y - p.y;
  const std::array<std::pair<double, double>, 4> edges = {
      {{-dx, p.x - box.x0}, {dx, box.x1 - p.x}, {-dy, p.y - box.y0}, {dy, box.y1 - p.y}}};
  for (const auto& [den, num] : edges) {
    if (den == 0) {
      if (num < 0) return false;
    } else if (const double t = num / den; den < 0) {
      t0 = std::max(t0, t);
    } else {
      t1 = std::min(t1, t);
    }
  }
  if (t0 > t1) return false;
  const Point start{p.x + t0 * dx, p.y + t0 * dy};
  q = {p.x + t1 * dx, p.y + t1 * dy};
  p = start;
  return true;
}

// Coverage of a disc of one radius for centres at 4x4 sub-pixel offsets, so that markers are
// stamped rather than computed point by point.
struct DiscStamps {
  int reach = 0;                             // pixels each side of the centre pixel
  std::array<std::vector<float>, 16> cover;  // [4 * sub_y + sub_x][(2 reach + 1)^2]

  explicit DiscStamps(double radius) : reach(static_cast<int>(std::ceil(radius + 0.5))) {
    const int side = 2 * reach + 1;
    for (int sub = 0; sub < 16; ++sub) {
      const double cx = (sub % 4 + 0.5) / 4, cy = (sub / 4 + 0.5) / 4;
      cover[sub].resize(static_cast<std::size_t>(side) * side);
      for (int j = 0; j < side; ++j) {
        for (int i = 0; i < side; ++i) {
          const double d = std::hypot(i - reach + 0.5 - cx, j - reach + 0.5 - cy);
          cover[sub][static_cast<std::size_t>(j) * side + i] =
              static_cast<float>(std::clamp(radius + 0.5 - d, 0.0, 1.0));
        }
      }
    }
  }
};

// Coverage (0..1) of one series over the plot area. Strokes combine by maximum, so joints and
// self-overlaps of a line stay the same shade.
class Layer {
 public:
  explicit Layer(const Box& area)
      : x0_(static_cast<int>(area.x0)),
        y0_(static_cast<int>(area.y0)),
        width_(std::max(1, static_cast<int>(area.width()))),
        height_(std::max(1, static_cast<int>(area.height()))),
        cover_(static_cast<std::size_t>(width_) * height_, 0.0f) {}

  int width() const { return width_; }

  // Round-capped segment pq of half width hw (a disc when p == q), antialiased by distance.
  void stroke(Point p, Point q, double hw) {
    const double reach = hw + 1;
    const Box bounds{x0_ - reach, y0_ - reach, x0_ + width_ + reach, y0_ + height_ + reach};
    if (!clip_segment(p, q, bounds)) return;
    // Walk along the major axis; per step only the pixels within reach across it are visited.
    const bool steep = std::abs(q.y - p.y) > std::abs(q.x - p.x);
    const double m0 = steep ? p.y : p.x, m1 = steep ? q.y : q.x;
    const double c0 = steep ? p.x : p.y, c1 = steep ? q.x : q.y;
    const double len2 = (q.x - p.x) * (q.x - p.x) + (q.y - p.y) * (q.y - p.y);
    const int i0 = static_cast<int>(std::floor(std::min(m0, m1) - reach));
    const int i1 = static_cast<int>(std::ceil(std::max(m0, m1) + reach));
    for (int i = i0; i <= i1; ++i) {
      const double mc = i + 0.5;
      double t0 = 0, t1 = 1;
      if (m1 != m0) {
        const double ta = (mc - reach - m0) / (m1 - m0);
        const double tb = (mc + reach - m0) / (m1 - m0);
        t0 = std::max(0.0, std::min(ta, tb));
        t1 = std::min(1.0, std::max(ta, tb));
        if (t0 > t1) continue;
      } else if (std::abs(mc - m0) > reach) {
        continue;
      }
      const double ca = c0 + t0 * (c1 - c0), cb = c0 + t1 * (c1 - c0);
      const int j0 = static_cast<int>(std::floor(std::min(ca, cb) - reach));
      const int j1 = static_cast<int>(std::ceil(std::max(ca, cb) + reach));
      for (int j = j0; j <= j1; ++j) {
        const double px = steep ? j + 0.5 : mc, py = steep ? mc : j + 0.5;
        double t = 0;
        if (len2 > 0) {
          t = std::clamp(((px - p.x) * (q.x - p.x) + (py - p.y) * (q.y - p.y)) / len2, 0.0, 1.0);
        }
        const double d = std::hypot(px - (p.x + t * (q.x - p.x)), py - (p.y + t * (q.y - p.y)));
        const double a = hw + 0.5 - d;
        if (a > 0) cover(steep ? j : i, steep ? i : j, std::min(a, 1.0));
      }
    }
  }

  // Antialiased disc at c from precomputed stamps (fast for many markers).
  void dot(Point c, const DiscStamps& stamps) {
    if (!std::isfinite(c.x) || !std::isfinite(c.y)) return;
    const double fx = std::floor(c.x), fy = std::floor(c.y);
    if (fx < x0_ - stamps.reach - 1 || fx > x0_ + width_ + stamps.reach ||
        fy < y0_ - stamps.reach - 1 || fy > y0_ + height_ + stamps.reach) {
      return;
    }
    const int sub = 4 * std::min(3, static_cast<int>((c.y - fy) * 4)) +
                    std::min(3, static_cast<int>((c.x - fx) * 4));
    const int side = 2 * stamps.reach + 1;
    const int bx = static_cast<int>(fx) - stamps.reach, by = static_cast<int>(fy) - stamps.reach;
    for (int j = 0; j < side; ++j) {
      for (int i = 0; i < side; ++i) {
        const float a = stamps.cover[sub][static_cast<std::size_t>(j) * side + i];
        if (a > 0) cover(bx + i, by + j, a);
      }
    }
  }

  // Keeps the larger coverage of this and another layer over the same area.
  void merge(const Layer& other) {
    for (std::size_t i = 0; i < cover_.size(); ++i)
      cover_[i] = std::max(cover_[i], other.cover_[i]);
  }

  // Total coverage inside a box (in canvas pixels).
  double sum(const Box& box) const {
    double total = 0;
    const int xa = std::max(0, static_cast<int>(box.x0) - x0_);
    const int xb = std::min(width_, static_cast<int>(std::ceil(box.x1)) - x0_);
    const int ya = std::max(0, static_cast<int>(box.y0) - y0_);
    const int yb = std::min(height_, static_cast<int>(std::ceil(box.y1)) - y0_);
    for (int y = ya; y < yb; ++y) {
      for (int x = xa; x < xb; ++x) total += cover_[static_cast<std::size_t>(y) * width_ + x];
    }
    return total;
  }

  // Paints the covered pixels in one colour.
  void composite(Canvas& canvas, Rgb c) const {
    for (int y = 0; y < height_; ++y) {
      for (int x = 0; x < width_; ++x) {
        const float a = cover_[static_cast<std::size_t>(y) * width_ + x];
        if (a > 0) canvas.blend(x0_ + x, y0_ + y, c, a);
      }
    }
  }

 private:
  void cover(int x, int y, double a) {
    x -= x0_;
    y -= y0_;
    if (x < 0 || y < 0 || x >= width_ || y >= height_) return;
    float& c = cover_[static_cast<std::size_t>(y) * width_ + x];
    c = std::max(c, static_cast<float>(a));
  }

  int x0_, y0_, width_, height_;
  std::vector<float> cover_;
};

// Text as stb_easy_font quads in font units: capitals span y 0..7, descenders reach 9, the
// advance is about 6 per character.
struct Glyphs {
  std::vector<Box> quads;
  double width = 0;
};

constexpr double kCapHeight = 7;

Glyphs layout_text(std::string_view text) {
  Glyphs g;
  double x = 0;
  std::string run;
  // Appends the quads of a run of printable ASCII characters.
  const auto flush = [&] {
    if (run.empty()) return;
    std::vector<char> buffer(run.size() * 1024 + 64);
    const int n = stb_easy_font_print(static_cast<float>(x), 0, run.data(), nullptr, buffer.data(),
                                      static_cast<int>(buffer.size()));
    for (int i = 0; i < n; ++i) {
      float corner[2][2];  // vertices 0 and 2 of the quad: opposite corners
      std::memcpy(corner[0], buffer.data() + (4 * i) * 16, sizeof(corner[0]));
      std::memcpy(corner[1], buffer.data() + (4 * i + 2) * 16, sizeof(corner[1]));
      g.quads.push_back({corner[0][0], corner[0][1], corner[1][0], corner[1][1]});
    }
    x += stb_easy_font_width(run.data());
    run.clear();
  };
  for (std::size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if (c == 0xC2 && i + 1 < text.size() && static_cast<unsigned char>(text[i + 1]) == 0xB0) {
      // The degree sign (UTF-8 C2 B0): a small raised ring.
      flush();
      for (const Box& b : {Box{0, 0, 3, 1}, Box{0, 2, 3, 3}, Box{0, 1, 1, 2}, Box{2, 1, 3, 2}}) {
        g.quads.push_back({x + b.x0, b.y0, x + b.x1, b.y1});
      }
      x += 4;
      ++i;
    } else if (c >= 0x80) {
      // Other non-ASCII characters: one '?' each, continuation bytes skipped.
      while (i + 1 < text.size() && (static_cast<unsigned char>(text[i + 1]) & 0xC0) == 0x80) ++i;
      run += '?';
    } else {
      run += (c < 32 || c == 127) ? ' ' : static_cast<char>(c);
    }
  }
  flush();
  g.width = x > 0 ? x - 1 : 0;  // the last advance includes a one-unit gap
  return g;
}

double text_width(std::string_view text, double scale) { return layout_text(text).width * scale; }

// The text, shortened with ".." if wider than max_width at a scale.
std::string fit_text(std::string text, double scale, double max_width) {
  while (text.size() > 2 && text_width(text, scale) > max_width) {
    text = text.substr(0, text.size() - 3) + "..";
  }
  return text;
}

// Draws text so that the point `anchor` of its box (fractions of width and cap height, e.g.
// {0.5, 0.5} for the centre) lands at `at`, rotated counter-clockwise by `degrees`.
void draw_text(Canvas& canvas, std::string_view text, Point at, double scale, Rgb color,
               Point anchor = {0, 0}, double degrees = 0) {
  const Glyphs g = layout_text(text);
  const double angle = degrees * std::numbers::pi / 180;
  const Point right{std::cos(angle), -std::sin(angle)};
  const Point down{std::sin(angle), std::cos(angle)};
  const bool aligned = std::abs(right.x * right.y) < 1e-9;
  const double ou = -anchor.x * g.width * scale, ov = -anchor.y * kCapHeight * scale;
  Point origin{at.x + ou * right.x + ov * down.x, at.y + ou * right.y + ov * down.y};
  // Whole-pixel origins keep upright text crisp.
  if (aligned) origin = {std::round(origin.x), std::round(origin.y)};
  const auto map = [&](double u, double v) {
    return Point{origin.x + scale * (u * right.x + v * down.x),
                 origin.y + scale * (u * right.y + v * down.y)};
  };
  for (const Box& q : g.quads) {
    const std::array<Point, 4> corners = {map(q.x0, q.y0), map(q.x1, q.y0), map(q.x1, q.y1),
                                          map(q.x0, q.y1)};
    if (aligned) {
      canvas.fill_rect({std::min(corners[0].x, corners[2].x), std::min(corners[0].y, corners[2].y),
                        std::max(corners[0].x, corners[2].x), std::max(corners[0].y, corners[2].y)},
                       color);
    } else {
      canvas.fill_quad(corners, color);
    }
  }
}

// Number of decimals that show multiples of step exactly (at most 6).
int decimals_for(double step) {
  int d = 0;
  double scaled = std::abs(step);
  while (d < 6 && std::abs(scaled - std::round(scaled)) > 1e-6 * std::max(1.0, scaled)) {
    scaled *= 10;
    ++d;
  }
  return d;
}

// Fixed-point text of v; "-0" becomes "0".
std::string fixed(double v, int decimals) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.*f", decimals, v);
  std::string s = buffer;
  if (s.find_first_not_of("-0.") == std::string::npos && s[0] == '-') s.erase(0, 1);
  return s;
}

// Drops trailing zeros after a decimal point ("2.50" -> "2.5", "3.0" -> "3").
std::string trim_zeros(std::string s) {
  if (s.find('.') == std::string::npos) return s;
  s.erase(s.find_last_not_of('0') + 1);
  if (s.back() == '.') s.pop_back();
  return s;
}

// Short label of one bar's value: "0.42", "3.5", "12", "2.5k".
std::string value_label(double v) {
  const double a = std::abs(v);
  if (a >= 1e4) return tick_labels({0, v}).back();
  return trim_zeros(fixed(v, a >= 100 ? 0 : a >= 10 ? 1 : a >= 0.01 || a == 0 ? 2 : 4));
}

// The range widened when empty (a single value) and padded by a fraction of its span per side.
Range padded(Range r, double margin) {
  // Far beyond any real data, but small enough that spans and margins stay finite.
  constexpr double kLimit = 1e306;
  r = {std::clamp(r.lo, -kLimit, kLimit), std::clamp(r.hi, -kLimit, kLimit)};
  if (!(r.hi - r.lo > std::abs(r.hi) * 1e-12)) {
    const double d = r.lo == 0 ? 1 : std::abs(r.lo) * 0.1;
    return {r.lo - d, r.hi + d};
  }
  const double d = (r.hi - r.lo) * margin;
  return {r.lo - d, r.hi + d};
}

// A caller's range if usable (finite, in order; a single value widened), else nullopt.
std::optional<Range> given_range(const std::optional<std::pair<double, double>>& range) {
  if (!range || !std::isfinite(range->first) || !std::isfinite(range->second)) return std::nullopt;
  const Range r{std::min(range->first, range->second), std::max(range->first, range->second)};
  return padded(r, 0);
}

// Nice ticks inside a range.
std::vector<double> ticks_within(Range r, int target) {
  std::vector<double> ticks;
  const double eps = (r.hi - r.lo) * 1e-9;
  for (double t : nice_ticks(r.lo, r.hi, target)) {
    if (t >= r.lo - eps && t <= r.hi + eps) ticks.push_back(t);
  }
  return ticks;
}

// Sizes derived from the image size so that larger images get larger text and strokes.
struct Style {
  double s = 2;            // text scale: font units to pixels
  double title_scale = 3;  // text scale of the title
  double pad = 8;          // general spacing
  double tick = 5;         // tick mark length
  double text_h = 14;      // cap height of normal text

  explicit Style(int width, int height) {
    s = std::clamp(std::round(std::min(width / 450.0, height / 270.0)), 1.0, 6.0);
    title_scale = s + std::floor(s / 2);
    pad = 4 * s;
    tick = 2.5 * s;
    text_h = kCapHeight * s;
  }
};

// Plot area and data ranges: maps data to pixels.
struct Frame {
  Box box;
  Range x, y;
  double px(double v) const { return box.x0 + (v - x.lo) / (x.hi - x.lo) * box.width(); }
  double py(double v) const { return box.y1 - (v - y.lo) / (y.hi - y.lo) * box.height(); }
};

// Column (or row) of pixels nearest to a coordinate, kept inside [lo, hi).
double snap(double v, double lo, double hi) {
  return std::clamp(std::floor(v), lo, std::max(lo, hi - 1));
}

// Light horizontal grid lines, y tick marks and labels, right-aligned left of the plot.
void draw_y_axis(Canvas& canvas, const Frame& f, const std::vector<double>& ticks,
                 const Style& st) {
  const std::vector<std::string> labels = tick_labels(ticks);
  for (std::size_t i = 0; i < ticks.size(); ++i) {
    const double y = snap(f.py(ticks[i]), f.box.y0, f.box.y1);
    canvas.fill_rect({f.box.x0, y, f.box.x1, y + 1}, kGrid);
    canvas.fill_rect({f.box.x0 - 1 - st.tick, y, f.box.x0 - 1, y + 1}, kFrame);
    draw_text(canvas, labels[i], {f.box.x0 - 1 - st.tick - st.pad * 0.75, y + 0.5}, st.s, kTickText,
              {1, 0.5});
  }
}

// One-pixel frame around a box, just outside it.
void draw_frame(Canvas& canvas, const Box& b, Rgb color = kFrame) {
  canvas.fill_rect({b.x0 - 1, b.y0 - 1, b.x1 + 1, b.y0}, color);
  canvas.fill_rect({b.x0 - 1, b.y1, b.x1 + 1, b.y1 + 1}, color);
  canvas.fill_rect({b.x0 - 1, b.y0, b.x0, b.y1}, color);
  canvas.fill_rect({b.x1, b.y0, b.x1 + 1, b.y1}, color);
}

// Title centred at the top; returns the y below it.
double draw_title(Canvas& canvas, const std::string& title, const Style& st) {
  if (title.empty()) return st.pad * 2;
  draw_text(canvas, fit_text(title, st.title_scale, canvas.width() - st.pad * 2),
            {canvas.width() / 2.0, st.pad * 2}, st.title_scale, kText, {0.5, 0});
  return st.pad * 4 + kCapHeight * st.title_scale;
}

// Y-axis label, reading upwards, centred along the plot's height at the left edge.
void draw_y_label(Canvas& canvas, const std::string& label, const Box& box, const Style& st) {
  if (label.empty()) return;
  draw_text(canvas, fit_text(label, st.s, box.height()), {st.pad * 1.5, (box.y0 + box.y1) / 2},
            st.s, kText, {0.5, 0}, 90);
}

// Width the y axis needs left of the plot: label, tick labels, tick marks.
double y_axis_width(const std::vector<double>& ticks, const std::string& label, const Style& st) {
  double widest = 0;
  for (const std::string& s : tick_labels(ticks)) widest = std::max(widest, text_width(s, st.s));
  return st.pad * 1.5 + (label.empty() ? 0 : st.text_h + st.pad * 1.5) + widest + st.pad * 0.75 +
         st.tick + 1;
}

// One legend row: a colour swatch and its label.
struct LegendEntry {
  std::string label;
  Rgb color;
  enum class Mark { kLine, kPoint, kBar } mark = Mark::kLine;
};

// Size of a legend box holding entries one per row.
Point legend_size(const std::vector<LegendEntry>& entries, const Style& st) {
  double widest = 0;
  for (const LegendEntry& e : entries) widest = std::max(widest, text_width(e.label, st.s));
  const double row = st.text_h + st.pad;
  return {st.pad * 2 + st.s * 10 + st.pad + widest,
          st.pad * 2 + row * static_cast<double>(entries.size()) - st.pad};
}

// Swatch of one legend entry, centred vertically at y, starting at x.
void draw_swatch(Canvas& canvas, const LegendEntry& e, double x, double y, const Style& st) {
  const double w = st.s * 10;
  switch (e.mark) {
    case LegendEntry::Mark::kLine:
      canvas.fill_rect({x, y - st.s / 2, x + w, y + st.s / 2}, e.color);
      break;
    case LegendEntry::Mark::kPoint:
      canvas.fill_disc({x + w / 2, y}, st.s * 1.75, e.color);
      break;
    case LegendEntry::Mark::kBar:
      canvas.fill_rect({x + w / 2 - st.text_h / 2, std::round(y - st.text_h / 2),
                        x + w / 2 + st.text_h / 2, std::round(y + st.text_h / 2)},
                       e.color);
      break;
  }
}

// Legend as a box of rows at a given top-left corner.
void draw_legend_box(Canvas& canvas, const std::vector<LegendEntry>& entries, Point at,
                     const Style& st) {
  const Point size = legend_size(entries, st);
  const Box box{std::round(at.x), std::round(at.y), std::round(at.x + size.x),
                std::round(at.y + size.y)};
  canvas.fill_rect(box, {255, 255, 255}, 0.88);
  draw_frame(canvas, box, kLegendBorder);
  const double row = st.text_h + st.pad;
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const double y = box.y0 + st.pad + row * static_cast<double>(i) + st.text_h / 2;
    draw_swatch(canvas, entries[i], box.x0 + st.pad, y, st);
    draw_text(canvas, entries[i].label, {box.x0 + st.pad * 2 + st.s * 10, y}, st.s, kText,
              {0, 0.5});
  }
}

// Points of one series in pixels, split into runs at non-finite values.
std::vector<std::vector<Point>> series_runs(const Series& series, const Frame& f) {
  std::vector<std::vector<Point>> runs(1);
  const std::size_t n =
      series.x.empty() ? series.y.size() : std::min(series.x.size(), series.y.size());
  for (std::size_t i = 0; i < n; ++i) {
    const double x = series.x.empty() ? static_cast<double>(i) : series.x[i];
    const double y = series.y[i];
    if (std::isfinite(x) && std::isfinite(y)) {
      // Points far off the plot are pulled in to where the direction of a line to them is the
      // same to the eye; this keeps all arithmetic finite.
      constexpr double kFar = 1e8;
      runs.back().push_back({std::clamp(f.px(x), -kFar, kFar), std::clamp(f.py(y), -kFar, kFar)});
    } else if (!runs.back().empty()) {
      runs.emplace_back();
    }
  }
  if (runs.back().empty()) runs.pop_back();
  return runs;
}

// Keeps, of each stretch of consecutive points within one pixel column, only the first, lowest,
// highest and last (in their order): the drawn line looks the same, however many points there are.
std::vector<Point> decimate(const std::vector<Point>& run) {
  std::vector<Point> out;
  std::size_t i = 0;
  while (i < run.size()) {
    const double column = std::floor(run[i].x);
    std::size_t lo = i, hi = i, j = i;
    for (; j < run.size() && std::floor(run[j].x) == column; ++j) {
      if (run[j].y < run[lo].y) lo = j;
      if (run[j].y > run[hi].y) hi = j;
    }
    std::array<std::size_t, 4> keep = {i, lo, hi, j - 1};
    std::sort(keep.begin(), keep.end());
    for (std::size_t k = 0; k < keep.size(); ++k) {
      if (k == 0 || keep[k] != keep[k - 1]) out.push_back(run[keep[k]]);
    }
    i = j;
  }
  return out;
}

// Range of the finite values of one coordinate over all series (x: index when x is empty).
std::optional<Range> data_range(const LinePlot& plot, bool along_x) {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  for (const Series& s : plot.series) {
    const std::size_t n = s.x.empty() ? s.y.size() : std::min(s.x.size(), s.y.size());
    for (std::size_t i = 0; i < n; ++i) {
      const double x = s.x.empty() ? static_cast<double>(i) : s.x[i];
      if (!std::isfinite(x) || !std::isfinite(s.y[i])) continue;
      const double v = along_x ? x : s.y[i];
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
  }
  if (lo > hi) return std::nullopt;
  return Range{lo, hi};
}

// X ticks whose labels fit side by side along the plot's width.
std::vector<double> fitting_x_ticks(Range r, double width, const Style& st) {
  std::vector<double> ticks;
  for (int target = 6; target >= 1; --target) {
    ticks = ticks_within(r, target);
    double total = 0;
    for (const std::string& s : tick_labels(ticks)) total += text_width(s, st.s) + st.pad * 2;
    if (total <= width) break;
  }
  return ticks;
}

// "no data" in the middle of an empty plot.
void draw_no_data(Canvas& canvas, const Box& box, const Style& st) {
  draw_text(canvas, "no data", {(box.x0 + box.x1) / 2, (box.y0 + box.y1) / 2}, st.s, kMuted,
            {0.5, 0.5});
}

void check_size(int width, int height) {
  if (width < kMinWidth || height < kMinHeight || width > 16384 || height > 16384) {
    throw UserError("plot size " + std::to_string(width) + "x" + std::to_string(height) +
                    " is out of range; expected from " + std::to_string(kMinWidth) + "x" +
                    std::to_string(kMinHeight) + " to 16384x16384 pixels");
  }
}

}  // namespace

Rgb default_color(int i) {
  static constexpr std::array<Rgb, 10> kPalette = {{{31, 119, 180},
                                                    {214, 39, 40},
                                                    {44, 160, 44},
                                                    {255, 127, 14},
                                                    {148, 103, 189},
                                                    {140, 86, 75},
                                                    {227, 119, 194},
                                                    {127, 127, 127},
                                                    {188, 189, 34},
                                                    {23, 190, 207}}};
  const int n = static_cast<int>(kPalette.size());
  return kPalette[((i % n) + n) % n];
}

std::vector<double> nice_ticks(double lo, double hi, int target) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) return {};
  if (lo > hi) std::swap(lo, hi);
  if (!(hi - lo > std::abs(hi) * 1e-12)) {
    const Range r = padded({lo, hi}, 0);
    lo = r.lo;
    hi = r.hi;
  }
  // Of the 1-2-5 steps around the raw one, the one whose interval count is nearest the target
  // (by ratio).
  const double want = std::max(1, target);
  const double raw = (hi - lo) / want;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  double step = magnitude;
  for (double m : {2.0, 5.0, 10.0}) {
    const double candidate = m * magnitude;
    if (std::abs(std::log((hi - lo) / candidate / want)) <
        std::abs(std::log((hi - lo) / step / want)) - 1e-9) {
      step = candidate;
    }
  }
  const double first = std::floor(lo / step + 1e-9);
  const double last = std::ceil(hi / step - 1e-9);
  std::vector<double> ticks;
  for (double i = first; i <= last && ticks.size() < 1000; ++i) {
    const double t = i * step;
    ticks.push_back(std::abs(t) < step * 1e-9 ? 0.0 : t);
  }
  return ticks;
}

std::vector<std::string> tick_labels(const std::vector<double>& ticks) {
  std::vector<std::string> labels;
  if (ticks.empty()) return labels;
  double largest = 0;
  for (double t : ticks) largest = std::max(largest, std::abs(t));
  double step = ticks.size() > 1 ? std::abs(ticks[1] - ticks[0]) : largest;
  if (!(step > 0)) step = 1;
  if (largest >= 1e13 || (largest > 0 && largest < 1e-2)) {
    // Scientific: "2.5e-4", with the mantissa's digits (ticks are round, so only a few).
    for (double t : ticks) {
      if (t == 0) {
        labels.push_back("0");
        continue;
      }
      int e = static_cast<int>(std::floor(std::log10(std::abs(t)) + 1e-9));
      const int decimals = std::min(3, decimals_for(t / std::pow(10.0, e)));
      std::string mantissa = trim_zeros(fixed(t / std::pow(10.0, e), decimals));
      if (mantissa == "10" || mantissa == "-10") {
        mantissa = mantissa[0] == '-' ? "-1" : "1";
        ++e;
      }
      labels.push_back(mantissa + "e" + std::to_string(e));
    }
    return labels;
  }
  // Plain, or with a k / M / G suffix for large values ("2.5k").
  double unit = 1;
  std::string suffix;
  if (largest >= 1e9) {
    unit = 1e9;
    suffix = "G";
  } else if (largest >= 1e6) {
    unit = 1e6;
    suffix = "M";
  } else if (largest >= 1e4) {
    unit = 1e3;
    suffix = "k";
  }
  const int decimals = decimals_for(step / unit);
  for (double t : ticks) {
    if (suffix.empty()) {
      labels.push_back(fixed(t, decimals));
    } else {
      const std::string s = trim_zeros(fixed(t / unit, decimals));
      labels.push_back(s == "0" ? s : s + suffix);
    }
  }
  return labels;
}

model::Image render_line_plot(const LinePlot& plot, int width, int height) {
  check_size(width, height);
  const Style st(width, height);
  Canvas canvas(width, height);

  // Ranges: the caller's, else the data's (y including reference lines) with a margin.
  const std::optional<Range> data_x = data_range(plot, true);
  std::optional<Range> data_y = data_range(plot, false);
  for (const auto& [value, label] : plot.h_lines) {
    if (!std::isfinite(value)) continue;
    data_y = Range{std::min(data_y ? data_y->lo : value, value),
                   std::max(data_y ? data_y->hi : value, value)};
  }
  Frame f;
  f.x = given_range(plot.x_range).value_or(data_x ? padded(*data_x, 0.02) : Range{0, 1});
  f.y = given_range(plot.y_range).value_or(data_y ? padded(*data_y, 0.05) : Range{0, 1});

  // Layout: title on top, y axis on the left, x axis below, all sized from their text.
  const double top = draw_title(canvas, plot.title, st);
  const std::vector<double> y_ticks = ticks_within(f.y, 5);
  const double bottom = height - st.pad * 1.5 - (plot.x_label.empty() ? 0 : st.text_h + st.pad) -
                        st.text_h - st.s * 2 - st.pad - st.tick - 1;
  const double left = std::round(y_axis_width(y_ticks, plot.y_label, st));
  const double right = std::round(width - st.pad * 4);
  f.box = {left, std::round(top), std::max(left + 1, right),
           std::max(std::round(top) + 1, std::round(bottom))};
  const std::vector<double> x_ticks = fitting_x_ticks(f.x, f.box.width(), st);

  // Grid and axes.
  draw_y_axis(canvas, f, y_ticks, st);
  const std::vector<std::string> x_labels = tick_labels(x_ticks);
  for (std::size_t i = 0; i < x_ticks.size(); ++i) {
    const double x = snap(f.px(x_ticks[i]), f.box.x0, f.box.x1);
    canvas.fill_rect({x, f.box.y0, x + 1, f.box.y1}, kGrid);
    canvas.fill_rect({x, f.box.y1 + 1, x + 1, f.box.y1 + 1 + st.tick}, kFrame);
    draw_text(canvas, x_labels[i], {x + 0.5, f.box.y1 + 1 + st.tick + st.pad * 0.75}, st.s,
              kTickText, {0.5, 0});
  }
  draw_text(canvas, fit_text(plot.x_label, st.s, f.box.width()),
            {(f.box.x0 + f.box.x1) / 2, height - st.pad * 1.5}, st.s, kText, {0.5, 1});
  draw_y_label(canvas, plot.y_label, f.box, st);

  // Data, one coverage layer per series, painted in order.
  Layer ink(f.box);
  const DiscStamps marker(st.s * 1.5);
  bool any = false;
  for (const Series& series : plot.series) {
    Layer layer(f.box);
    for (std::vector<Point> run : series_runs(series, f)) {
      any = true;
      if (series.points) {
        for (const Point& p : run) layer.dot(p, marker);
        continue;
      }
      if (run.size() == 1) layer.dot(run[0], marker);
      if (run.size() > 2 * static_cast<std::size_t>(layer.width())) run = decimate(run);
      for (std::size_t i = 1; i < run.size(); ++i) layer.stroke(run[i - 1], run[i], st.s / 2);
    }
    layer.composite(canvas, series.color);
    ink.merge(layer);
  }
  if (!any) draw_no_data(canvas, f.box, st);

  // Dashed reference lines, labelled at their right end.
  for (const auto& [value, label] : plot.h_lines) {
    const double y = f.py(value);
    if (!std::isfinite(y) || y < f.box.y0 || y > f.box.y1) continue;
    const double thick = std::max(1.0, st.s * 0.75), dash = st.s * 4, gap = st.s * 3;
    for (double x = f.box.x0; x < f.box.x1; x += dash + gap) {
      canvas.fill_rect({x, y - thick / 2, std::min(x + dash, f.box.x1), y + thick / 2}, kRefLine);
    }
    if (label.empty()) continue;
    const double w = text_width(label, st.s);
    const bool above = y - st.text_h - st.pad > f.box.y0;
    const Point at{f.box.x1 - st.pad, above ? y - st.pad * 0.75 : y + st.pad * 0.75};
    canvas.fill_rect({at.x - w - st.s * 2, above ? at.y - st.text_h - st.s * 2 : at.y - st.s,
                      at.x + st.s * 2, above ? at.y + st.s : at.y + st.text_h + st.s * 3},
                     {255, 255, 255}, 0.8);
    draw_text(canvas, label, at, st.s, kRefLine, {1, above ? 1.0 : 0.0});
  }
  draw_frame(canvas, f.box);

  // Legend in the corner of the plot that hides the least data.
  std::vector<LegendEntry> entries;
  for (const Series& s : plot.series) {
    if (s.label.empty()) continue;
    entries.push_back({fit_text(s.label, st.s, f.box.width() / 2), s.color,
                       s.points ? LegendEntry::Mark::kPoint : LegendEntry::Mark::kLine});
  }
  if (!entries.empty()) {
    const Point size = legend_size(entries, st);
    const double inset = st.pad;
    const std::array<Point, 4> corners = {{{f.box.x1 - inset - size.x, f.box.y0 + inset},
                                           {f.box.x0 + inset, f.box.y0 + inset},
                                           {f.box.x1 - inset - size.x, f.box.y1 - inset - size.y},
                                           {f.box.x0 + inset, f.box.y1 - inset - size.y}}};
    Point best = corners[0];
    double least = std::numeric_limits<double>::infinity();
    for (const Point& c : corners) {
      const double hidden = ink.sum({c.x, c.y, c.x + size.x, c.y + size.y});
      if (hidden < least - 1e-9) {
        least = hidden;
        best = c;
      }
    }
    draw_legend_box(canvas, entries, best, st);
  }
  return std::move(canvas).release();
}

model::Image render_bar_chart(const BarChart& chart, int width, int height) {
  check_size(width, height);
  const Style st(width, height);
  Canvas canvas(width, height);
  const std::size_t n = chart.categories.size();
  const std::size_t groups = chart.values.size();
  const auto value = [&](std::size_t g, std::size_t c) {
    return c < chart.values[g].size() ? chart.values[g][c] : kNaN;
  };

  // Range: from zero (or below it) to the largest value, with headroom.
  double lo = 0, hi = 0;
  bool any = false;
  for (std::size_t g = 0; g < groups; ++g) {
    for (std::size_t c = 0; c < n; ++c) {
      if (!std::isfinite(value(g, c))) continue;
      lo = std::min(lo, value(g, c));
      hi = std::max(hi, value(g, c));
      any = true;
    }
  }
  Frame f;
  f.x = {0, std::max<double>(1, static_cast<double>(n))};
  if (const std::optional<Range> given = given_range(chart.y_range)) {
    f.y = *given;
  } else if (hi > lo) {
    const Range r = padded({lo, hi}, 0.05);
    f.y = {lo < 0 ? r.lo : 0, hi > 0 ? r.hi : 0};
  }

  // Legend: one row of entries under the title.
  double top = draw_title(canvas, chart.title, st);
  std::vector<LegendEntry> entries;
  for (std::size_t g = 0; g < groups && g < chart.group_labels.size(); ++g) {
    if (chart.group_labels[g].empty()) continue;
    entries.push_back(
        {chart.group_labels[g],
         g < chart.colors.size() ? chart.colors[g] : default_color(static_cast<int>(g)),
         LegendEntry::Mark::kBar});
  }
  if (!entries.empty()) {
    const double swatch = st.s * 10 + st.pad;
    double total = 0;
    for (const LegendEntry& e : entries) total += swatch + text_width(e.label, st.s) + st.pad * 3;
    double x = std::max(st.pad, (width - total + st.pad * 3) / 2);
    for (const LegendEntry& e : entries) {
      const double y = top + st.text_h / 2;
      draw_swatch(canvas, e, x, y, st);
      draw_text(canvas, e.label, {x + swatch, y}, st.s, kText, {0, 0.5});
      x += swatch + text_width(e.label, st.s) + st.pad * 3;
    }
    top += st.text_h + st.pad * 2;
  }

  // Category labels: level when they fit their slot, else slanted at 45 degrees (and shortened
  // if they would take more than a third of the height).
  const std::vector<double> y_ticks = ticks_within(f.y, 5);
  double left = std::round(y_axis_width(y_ticks, chart.y_label, st));
  const double right = std::round(width - st.pad * 4);
  std::vector<std::string> names = chart.categories;
  double widest = 0;
  for (const std::string& s : names) widest = std::max(widest, text_width(s, st.s));
  double slot = (right - left) / std::max<double>(1, static_cast<double>(n));
  const bool slanted = widest > slot - st.pad;
  const double diagonal = std::sqrt(0.5);
  double drop = st.text_h + st.s * 2;
  if (slanted) {
    const double room = height / 3.0 / diagonal - st.text_h;
    for (std::string& s : names) {
      while (s.size() > 3 && text_width(s, st.s) > room) s = s.substr(0, s.size() - 3) + "..";
    }
    widest = 0;
    for (const std::string& s : names) widest = std::max(widest, text_width(s, st.s));
    drop = (widest + st.text_h) * diagonal;
    // The first label reaches left of its slot; keep it inside the image.
    if (!names.empty()) {
      const double reach = (text_width(names[0], st.s) + st.text_h / 2) * diagonal;
      left = std::max(left, std::round(st.pad + reach - slot / 2));
      slot = (right - left) / std::max<double>(1, static_cast<double>(n));
    }
  }
  const double bottom = height - st.pad * 1.5 - drop - st.pad * 0.75 - st.tick - 1;
  f.box = {left, std::round(top), std::max(left + 1, right),
           std::max(std::round(top) + 1, std::round(bottom))};

  // Axes, bars, and value labels where they fit above their bars.
  draw_y_axis(canvas, f, y_ticks, st);
  draw_y_label(canvas, chart.y_label, f.box, st);
  const double base = snap(f.py(std::clamp(0.0, f.y.lo, f.y.hi)), f.box.y0, f.box.y1 + 1);
  const double group_w = slot * 0.8;
  const double bar_w = group_w / std::max<double>(1, static_cast<double>(groups));
  const double gap = bar_w >= 6 ? 1 : 0;
  for (std::size_t c = 0; c < n; ++c) {
    const double center = f.box.x0 + slot * (static_cast<double>(c) + 0.5);
    const double x = std::floor(center);
    canvas.fill_rect({x, f.box.y1 + 1, x + 1, f.box.y1 + 1 + st.tick}, kFrame);
    const Point at{center, f.box.y1 + 1 + st.tick + st.pad * 0.75};
    if (slanted) {
      draw_text(canvas, names[c], {at.x + st.s, at.y + st.text_h * diagonal / 2}, st.s, kTickText,
                {1, 0.5}, 45);
    } else {
      draw_text(canvas, names[c], at, st.s, kTickText, {0.5, 0});
    }
    for (std::size_t g = 0; g < groups; ++g) {
      const double v = value(g, c);
      if (!std::isfinite(v)) continue;
      const Rgb color =
          g < chart.colors.size() ? chart.colors[g] : default_color(static_cast<int>(g));
      const double x0 = std::round(center - group_w / 2 + bar_w * static_cast<double>(g));
      const double x1 = std::max(x0 + 1, std::round(x0 + bar_w) - gap);
      const double y = std::round(std::clamp(f.py(v), f.box.y0, f.box.y1));
      canvas.fill_rect({x0, std::min(y, base), x1, std::max(y, base)}, color);
      // The value at the bar's end: outside when there is room, else just inside it.
      const std::string label = value_label(v);
      if (text_width(label, st.s) > x1 - x0 + gap) continue;
      const bool up = v >= 0;
      const double need = st.text_h + st.s * 4;
      const double cx = (x0 + x1) / 2;
      if ((up ? y - f.box.y0 : f.box.y1 - y) >= need) {
        draw_text(canvas, label, {cx, up ? y - st.s * 2 : y + st.s * 2}, st.s, kTickText,
                  {0.5, up ? 1.0 : 0.0});
      } else if (std::abs(base - y) >= need) {
        const bool light = 0.3 * color.r + 0.59 * color.g + 0.11 * color.b > 160;
        draw_text(canvas, label, {cx, up ? y + st.s * 2 : y - st.s * 2}, st.s,
                  light ? kText : Rgb{255, 255, 255}, {0.5, up ? 0.0 : 1.0});
      }
    }
  }
  if (f.y.lo < 0 && f.y.hi > 0) canvas.fill_rect({f.box.x0, base, f.box.x1, base + 1}, kFrame);
  if (!any) draw_no_data(canvas, f.box, st);
  draw_frame(canvas, f.box);
  return std::move(canvas).release();
}

void write_png(const model::Image& image, const std::filesystem::path& file) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgb.size() != 3 * static_cast<std::size_t>(image.width) * image.height) {
    throw UserError("cannot write plot '" + file.string() + "': the image is " +
                    std::to_string(image.width) + "x" + std::to_string(image.height) + " with " +
                    std::to_string(image.rgb.size()) + " bytes; expected a non-empty RGB image");
  }
  const std::vector<std::uint8_t> png = model::encode_png(image);
  if (png.empty()) throw UserError("cannot encode plot '" + file.string() + "' as PNG");
  std::error_code ec;
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path(), ec);
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  if (!out) {
    const std::string why = ec ? ec.message() : std::strerror(errno);
    throw UserError("cannot write plot '" + file.string() + "': " + why +
                    "; expected a writable file path");
  }
  out.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  out.close();
  if (!out) throw UserError("cannot write plot '" + file.string() + "': writing failed");
}

}  // namespace cradle::eval

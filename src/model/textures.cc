// Procedural textures of the infant. Every image is a colour function of the direction from the
// centre of a cube map, sampled at each texel of each face, so neighbouring faces meet without
// seams and a feature may span two faces.
#include "model/textures.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace cradle::model {
namespace {

// Edge lengths in texels of the square cube faces. A cube texture stores 6 faces of size^2 * 3
// bytes (missing faces included), so the 7 head textures dominate the model's ntexdata.
constexpr int kHeadSize = 192;
constexpr int kEyeSize = 96;
constexpr int kSleeveSize = 64;

// Cube faces in MuJoCo's (and OpenGL's) order, with their MJCF file attributes.
enum Face { kPosX, kNegX, kPosY, kNegY, kPosZ, kNegZ };
constexpr std::array<std::string_view, 6> kFaceAttributes = {"fileright", "fileleft",  "fileup",
                                                             "filedown",  "filefront", "fileback"};

constexpr double kPi = std::numbers::pi;

// A colour with channels in [0, 1].
struct Color {
  double r = 0;
  double g = 0;
  double b = 0;
};

// A colour from 8-bit channels.
constexpr Color rgb8(int r, int g, int b) { return {r / 255.0, g / 255.0, b / 255.0}; }

// Palette. The head's skin equals the skin material's rgba and the unset -z face's rgb1.
constexpr Color kSkin = {0.95, 0.8, 0.5};
constexpr Color kSkinShade = rgb8(214, 158, 98);
constexpr Color kSkinLight = rgb8(250, 222, 160);
constexpr Color kBlush = rgb8(240, 140, 118);
constexpr Color kEar = rgb8(228, 172, 108);
constexpr Color kHair = rgb8(116, 76, 44);
constexpr Color kHairLight = rgb8(150, 104, 62);
constexpr Color kBrow = rgb8(128, 86, 52);
constexpr Color kLip = rgb8(186, 92, 78);
constexpr Color kMouth = rgb8(96, 32, 36);
constexpr Color kTongue = rgb8(222, 112, 112);
constexpr Color kTeeth = rgb8(246, 242, 232);
constexpr Color kWhite = {1, 1, 1};
constexpr Color kIris = rgb8(104, 70, 40);
constexpr Color kIrisLight = rgb8(158, 116, 64);
constexpr Color kLimbus = rgb8(52, 34, 22);
constexpr Color kPupil = rgb8(12, 10, 10);
constexpr Color kShirt = {0.1, 0.5, 0.0};
constexpr Color kShirtStripe = {0.17, 0.58, 0.07};

// Linear blend from a (t = 0) to b (t = 1).
Color mix(const Color& a, const Color& b, double t) {
  return {a.r + (b.r - a.r) * t, a.g + (b.g - a.g) * t, a.b + (b.b - a.b) * t};
}

// Colour scaled channel-wise.
Color scale(const Color& c, double k) { return {c.r * k, c.g * k, c.b * k}; }

// Square of a number.
double sq(double x) { return x * x; }

// Hermite step from 0 at e0 to 1 at e1 (e0 > e1 gives the falling step).
double smoothstep(double e0, double e1, double x) {
  const double t = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
  return t * t * (3 - 2 * t);
}

// Antialiased coverage of a shape from its signed distance (negative inside) and the texel width.
double coverage(double distance, double texel) {
  return std::clamp(0.5 - distance / texel, 0.0, 1.0);
}

// A direction from the cube centre (not normalised).
struct Dir {
  double x = 0;
  double y = 0;
  double z = 0;
};

// Unit vector along a direction, and the dot product of two directions.
Dir normalized(const Dir& d) {
  const double n = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);
  return {d.x / n, d.y / n, d.z / n};
}

double dot(const Dir& a, const Dir& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

// Direction through texture coordinates (s, t) in [0, 1] of a face: the inverse of OpenGL's cube
// map face selection. MuJoCo uploads PNG faces unflipped, so image row 0 is t = 0 and column 0 is
// s = 0 (on +x: rows run from +y to -y, columns from +z to -z).
Dir face_direction(Face face, double s, double t) {
  const double a = 2 * s - 1;
  const double b = 2 * t - 1;
  switch (face) {
    case kPosX:
      return {1, -b, -a};
    case kNegX:
      return {-1, -b, a};
    case kPosY:
      return {a, 1, b};
    case kNegY:
      return {a, -1, -b};
    case kPosZ:
      return {a, -b, 1};
    case kNegZ:
      return {-a, -b, -1};
  }
  return {1, 0, 0};
}

// Writes a colour as 3 bytes.
void store(const Color& c, std::uint8_t* out) {
  for (double channel : {c.r, c.g, c.b}) {
    *out++ = static_cast<std::uint8_t>(std::lround(std::clamp(channel, 0.0, 1.0) * 255));
  }
}

// One cube face image from shade(direction, texel width in face-plane units).
template <typename Shade>
Image render_face(Face face, int size, const Shade& shade) {
  Image image{size, size, std::vector<std::uint8_t>(static_cast<std::size_t>(size) * size * 3)};
  const double texel = 2.0 / size;
  std::uint8_t* out = image.rgb.data();
  for (int row = 0; row < size; ++row) {
    for (int col = 0; col < size; ++col) {
      store(shade(face_direction(face, (col + 0.5) / size, (row + 0.5) / size), texel), out);
      out += 3;
    }
  }
  return image;
}

// Repaints a rendered cube face: paint(colour, direction, texel width) for every texel.
template <typename Paint>
void paint_face(Image& image, Face face, const Paint& paint) {
  const int size = image.width;
  const double texel = 2.0 / size;
  std::uint8_t* px = image.rgb.data();
  for (int row = 0; row < size; ++row) {
    for (int col = 0; col < size; ++col, px += 3) {
      const Color c = paint(rgb8(px[0], px[1], px[2]),
                            face_direction(face, (col + 0.5) / size, (row + 0.5) / size), texel);
      store(c, px);
    }
  }
}

// Pseudo-random value in [0, 1] for an integer lattice point (fixed integer hash).
double lattice_hash(int x, int y, int z) {
  std::uint32_t h = static_cast<std::uint32_t>(x) * 73856093u ^
                    static_cast<std::uint32_t>(y) * 19349663u ^
                    static_cast<std::uint32_t>(z) * 83492791u;
  h ^= h >> 13;
  h *= 0x5bd1e995u;
  h ^= h >> 15;
  return (h & 0xffffu) / 65535.0;
}

// Deterministic value noise in [0, 1]: lattice values smoothly interpolated in 3D.
double value_noise(double x, double y, double z) {
  const double fx = std::floor(x), fy = std::floor(y), fz = std::floor(z);
  const int ix = static_cast<int>(fx), iy = static_cast<int>(fy), iz = static_cast<int>(fz);
  const double tx = smoothstep(0, 1, x - fx), ty = smoothstep(0, 1, y - fy);
  const double tz = smoothstep(0, 1, z - fz);
  double plane[2];
  for (int k = 0; k < 2; ++k) {
    const double a = lattice_hash(ix, iy, iz + k) +
                     (lattice_hash(ix + 1, iy, iz + k) - lattice_hash(ix, iy, iz + k)) * tx;
    const double b = lattice_hash(ix, iy + 1, iz + k) +
                     (lattice_hash(ix + 1, iy + 1, iz + k) - lattice_hash(ix, iy + 1, iz + k)) * tx;
    plane[k] = a + (b - a) * ty;
  }
  return plane[0] + (plane[1] - plane[0]) * tz;
}

// A point in a tangent plane of the head: on the face plane (x = 1), u runs towards MIMo's left
// (+y, the viewer's right) and v up (+z); one unit is 45 degrees at the plane's centre.
struct Point {
  double u = 0;
  double v = 0;
};

// Euclidean distance between two points.
double distance(const Point& a, const Point& b) { return std::hypot(a.u - b.u, a.v - b.v); }

// Signed distance to a segment stroke of half thickness `half`.
double segment_distance(const Point& p, const Point& a, const Point& b, double half) {
  const double du = b.u - a.u, dv = b.v - a.v;
  const double t =
      std::clamp(((p.u - a.u) * du + (p.v - a.v) * dv) / (du * du + dv * dv), 0.0, 1.0);
  return distance(p, {a.u + du * t, a.v + dv * t}) - half;
}

// Signed distance to an ellipse (approximate away from the outline, exact enough for shading).
double ellipse_distance(const Point& p, const Point& centre, double ru, double rv) {
  const double q = std::hypot((p.u - centre.u) / ru, (p.v - centre.v) / rv);
  return (q - 1) * std::min(ru, rv);
}

// Signed distance to a stroke along the curve v = curve(x), u = u0 + half_width * x for x in
// [-1, 1], with round caps; thick(x) is the half thickness along the stroke.
template <typename Curve, typename Thick>
double curve_distance(const Point& p, double u0, double half_width, const Curve& curve,
                      const Thick& thick) {
  const double x = (p.u - u0) / half_width;
  if (std::abs(x) >= 1) {
    const double end = x > 0 ? 1 : -1;
    return distance(p, {u0 + half_width * end, curve(end)}) - thick(end);
  }
  constexpr double kStep = 1e-3;
  const double slope = (curve(x + kStep) - curve(x - kStep)) / (2 * kStep * half_width);
  return std::abs(p.v - curve(x)) / std::sqrt(1 + slope * slope) - thick(x);
}

// Signed distance to a closed polygon (negative inside).
double polygon_distance(const Point& p, const std::vector<Point>& polygon) {
  double nearest = 1e9;
  bool inside = false;
  for (std::size_t i = 0, j = polygon.size() - 1; i < polygon.size(); j = i++) {
    const Point& a = polygon[j];
    const Point& b = polygon[i];
    nearest = std::min(nearest, segment_distance(p, a, b, 0));
    if ((a.v > p.v) != (b.v > p.v) && p.u < a.u + (b.u - a.u) * (p.v - a.v) / (b.v - a.v)) {
      inside = !inside;
    }
  }
  return inside ? -nearest : nearest;
}

// How one facial expression shapes brows, mouth and skin (face-plane units, see Point).
struct Expression {
  double brow_inner;   // raise of the brow ends next to the nose
  double brow_outer;   // raise of the outer brow ends
  double brow_arch;    // upward bulge of the brow middles
  double brow_tilt;    // raise of MIMo's left brow and lowering of his right one
  double mouth_width;  // half width
  double mouth_curve;  // raise of the corners over the middle (> 0 smiles)
  double mouth_skew;   // raise of MIMo's left corner over his right one
  double mouth_wave;   // wobble along the lips
  double mouth_open;   // half height of the opening at the middle (0: closed, a line)
  double mouth_round;  // opening profile exponent: 1 lens, 0.5 oval, less is boxy
  double mouth_top;    // share of the opening above the centre line
  bool teeth;          // upper teeth show
  bool tongue;         // tongue shows
  double blush;        // cheek blush strength
  double forehead;     // forehead crease strength
  double wrinkle;      // nose crease strength
};

// Expressions in emote_names() order.
constexpr std::array<Expression, 7> kExpressions = {{
    // default: calm, a hint of a smile
    {0.0, -0.01, 0.03, 0, 0.12, 0.035, 0, 0, 0, 1, 0.5, false, false, 0.3, 0, 0},
    // happy: raised arched brows, open smile
    {0.02, 0.01, 0.05, 0, 0.17, 0.06, 0, 0, 0.085, 1, 0.12, true, true, 0.5, 0, 0},
    // sad: inner brow ends up, corners down
    {0.08, -0.03, -0.005, 0, 0.12, -0.06, 0, 0, 0, 1, 0.5, false, false, 0.15, 0.25, 0},
    // surprised: high round brows, round open mouth
    {0.09, 0.07, 0.06, 0, 0.075, 0, 0, 0, 0.095, 0.5, 0.5, false, false, 0.3, 0.4, 0},
    // angry: brows drawn down to the nose, bared teeth, flushed
    {-0.07, 0.05, -0.01, 0, 0.13, -0.045, 0, 0, 0.03, 0.35, 0.5, true, false, 0.55, 0, 0.2},
    // disgusted: lowered uneven brows, sneering lip, nose creases
    {-0.04, 0.0, 0.0, 0.04, 0.13, -0.02, 0.07, 0.01, 0, 1, 0.5, false, false, 0.25, 0, 0.6},
    // scared: inner brow ends up, wide wobbly open mouth, pale
    {0.09, 0.01, 0.0, 0, 0.16, -0.04, 0, 0.012, 0.045, 0.5, 0.55, true, false, 0.05, 0.45, 0},
}};

// Face layout (face-plane units). The eye spheres' centres project to (+-0.408, -0.102) seen
// from the head centre, and each covers a disc of radius ~0.13 there.
constexpr double kEyeU = 0.408;
constexpr double kEyeV = -0.102;
constexpr double kBrowU = 0.41;  // brow middle
constexpr double kBrowHalf = 0.15;
constexpr double kBrowV = 0.15;
constexpr double kNoseV = -0.33;
constexpr double kMouthV = -0.56;

// Mouth centre line and the upper and lower edges of its opening, for x in [-1, 1] across.
double mouth_centre(const Expression& e, double x) {
  return kMouthV + e.mouth_curve * x * x + e.mouth_skew * x + e.mouth_wave * std::sin(3 * kPi * x);
}
double mouth_opening(const Expression& e, double x) {
  return e.mouth_open * std::pow(std::max(0.0, 1 - x * x), e.mouth_round);
}
double mouth_upper(const Expression& e, double x) {
  return mouth_centre(e, x) + 2 * e.mouth_top * mouth_opening(e, x);
}
double mouth_lower(const Expression& e, double x) {
  return mouth_centre(e, x) - 2 * (1 - e.mouth_top) * mouth_opening(e, x);
}

// Outline of an open mouth: the upper edge left to right, then the lower edge back, sampled
// densest at the corners.
std::vector<Point> mouth_outline(const Expression& e) {
  constexpr int kSamples = 40;
  std::vector<Point> outline;
  for (int i = 0; i <= kSamples; ++i) {
    const double x = -std::cos(kPi * i / kSamples);
    outline.push_back({e.mouth_width * x, mouth_upper(e, x)});
  }
  for (int i = kSamples - 1; i > 0; --i) {
    const double x = -std::cos(kPi * i / kSamples);
    outline.push_back({e.mouth_width * x, mouth_lower(e, x)});
  }
  return outline;
}

// Head colour without the expression: skin, hair, ears, nose, eye sockets. Each feature is
// evaluated only near where it shows.
Color head_base(const Dir& raw, double texel) {
  const Dir d = normalized(raw);
  Color c = kSkin;

  // Short hair: a cap around an axis tilted back from the top, with an irregular soft hairline,
  // a forelock, and faint strands radiating from the crown.
  constexpr Dir kAxis = {-0.410365, 0, 0.911922};  // normalised (-0.45, 0, 1)
  const double h = dot(d, kAxis);
  if (h > 0.15) {  // below every hairline
    const double az = std::atan2(d.y, d.x * kAxis.z - d.z * kAxis.x);
    const double tuft = 0.12 * std::exp(-sq(az / 0.22));  // forelock in the middle of the front
    const double edge = 0.42 + 0.018 * std::sin(7 * az) + 0.01 * std::sin(19 * az + 1) - tuft;
    const double fuzz = 0.05 * value_noise(d.x * 30, d.y * 30, d.z * 30);
    const double density = smoothstep(edge - 0.04, edge + 0.1, h + fuzz);
    if (density > 0) {
      const double from_crown = std::sqrt(std::max(0.0, 1 - h * h));
      const double wobble = 3 * value_noise(d.x * 5, d.y * 5, d.z * 5);
      const double strands = 0.5 + 0.5 * std::sin(70 * az + 10 * h + wobble);
      const double contrast = 0.35 * smoothstep(0.05, 0.35, from_crown);
      const double tone = 0.65 * value_noise(d.x * 8 + 7, d.y * 8, d.z * 8) + contrast * strands;
      c = mix(c, mix(kHair, kHairLight, tone), 0.9 * density);
    }
  }

  // Features on the front, in face-plane coordinates.
  if (d.x > 0.3) {
    const Point p{d.y / d.x, d.z / d.x};

    // Soft shadow ring around each eye socket.
    for (double side : {-1.0, 1.0}) {
      const double r = distance(p, {side * kEyeU, kEyeV});
      if (r < 0.3) c = mix(c, kSkinShade, 0.18 * std::exp(-sq((r - 0.15) / 0.035)));
    }

    // Nose: highlight on the bridge, shadow arc under the tip, nostrils.
    if (std::abs(p.u) < 0.15 && std::abs(p.v - kNoseV) < 0.15) {
      c = mix(c, kSkinLight, 0.35 * std::exp(-sq(distance(p, {0, kNoseV + 0.05}) / 0.04)));
      const double tip = curve_distance(
          p, 0, 0.065, [](double x) { return kNoseV - 0.03 + 0.025 * x * x; },
          [](double x) { return 0.011 * (1 - 0.5 * x * x); });
      c = mix(c, kSkinShade, 0.85 * coverage(tip, texel * 1.5));
      for (double side : {-1.0, 1.0}) {
        const double nostril = ellipse_distance(p, {side * 0.032, kNoseV - 0.04}, 0.016, 0.01);
        c = mix(c, scale(kSkinShade, 0.8), 0.7 * coverage(nostril, texel));
      }
    }
  }

  // Ears on the sides: a rosier oval with a C-shaped rim opening to the front.
  if (std::abs(d.y) > 0.3) {
    const Point q{d.x / std::abs(d.y), d.z / std::abs(d.y)};
    const Point centre{-0.06, -0.1};
    constexpr double kRu = 0.15, kRv = 0.24;
    if (std::abs(q.u - centre.u) < 0.3 && std::abs(q.v - centre.v) < 0.4) {
      c = mix(c, kEar, 0.6 * coverage(ellipse_distance(q, centre, kRu, kRv), texel * 4));
      const double ang = std::atan2((q.v - centre.v) / kRv, (q.u - centre.u) / kRu);
      const double back = smoothstep(0.35, 0.1, std::cos(ang));  // 0 on the front side
      if (back > 0) {
        const double rim = std::abs(ellipse_distance(q, centre, kRu * 0.66, kRv * 0.7)) - 0.012;
        c = mix(c, kSkinShade, 0.7 * back * coverage(rim, texel * 1.5));
      }
    }
  }
  return c;
}

// Adds an expression's brows, mouth, blush and creases on the face plane; `mouth` is
// mouth_outline(e) when the mouth is open.
Color paint_expression(Color c, const Point& p, double texel, const Expression& e,
                       const std::vector<Point>& mouth) {
  // Cheek blush (negligible beyond 4.5 sigma).
  for (double side : {-1.0, 1.0}) {
    const double r = distance(p, {side * 0.47, -0.36});
    if (r < 0.4) c = mix(c, kBlush, e.blush * std::exp(-r * r / (2 * 0.09 * 0.09)));
  }

  // Forehead creases (raised brows) and nose creases (disgust, anger).
  if (e.forehead > 0 && std::abs(p.u) < 0.2 && p.v > 0.3 && p.v < 0.5) {
    for (double level : {0.36, 0.43}) {
      const double crease = curve_distance(
          p, 0, 0.15, [level](double x) { return level + 0.012 * std::sin(3 * x) - 0.01 * x * x; },
          [](double x) { return 0.006 * (1 - 0.6 * x * x); });
      c = mix(c, kSkinShade, e.forehead * coverage(crease, texel * 1.5));
    }
  }
  if (e.wrinkle > 0 && std::abs(p.u) < 0.13 && p.v > -0.3 && p.v < -0.14) {
    for (double side : {-1.0, 1.0}) {
      for (double dv : {0.0, -0.05}) {
        const double crease =
            segment_distance(p, {side * 0.055, -0.17 + dv}, {side * 0.1, -0.225 + dv}, 0.006);
        c = mix(c, kSkinShade, e.wrinkle * coverage(crease, texel * 1.5));
      }
    }
  }

  // Brows: x runs from the inner end (-1) to the outer end (+1) on each side.
  for (double side : {-1.0, 1.0}) {
    if (side * p.u < 0.2 || side * p.u > 0.62 || std::abs(p.v - kBrowV - 0.03) > 0.15) continue;
    const auto height = [&](double x) {
      return kBrowV + e.brow_inner * (1 - x) / 2 + e.brow_outer * (1 + x) / 2 +
             e.brow_arch * (1 - x * x) + e.brow_tilt * side;
    };
    const Point local{side * p.u, p.v};  // mirror MIMo's right brow onto his left one
    const double brow = curve_distance(local, kBrowU, kBrowHalf, height,
                                       [](double x) { return 0.026 - 0.009 * (x + 1) / 2; });
    c = mix(c, kBrow, 0.95 * coverage(brow, texel));
  }

  // Mouth centre line, then either a closed line or an opening with lips, teeth and tongue.
  if (std::abs(p.u) > e.mouth_width + 0.03 || std::abs(p.v - kMouthV) > 0.2) return c;
  if (e.mouth_open <= 0) {
    const double line = curve_distance(
        p, 0, e.mouth_width, [&e](double x) { return mouth_centre(e, x); },
        [](double x) { return 0.012 - 0.005 * x * x; });
    return mix(c, kLip, coverage(line, texel));
  }
  const double inside = polygon_distance(p, mouth);
  Color fill = kMouth;
  const double x = std::clamp(p.u / e.mouth_width, -1.0, 1.0);
  if (e.teeth) fill = mix(fill, kTeeth, coverage(mouth_upper(e, x) - 0.028 - p.v, texel));
  if (e.tongue) {
    const double tongue =
        ellipse_distance(p, {0, mouth_lower(e, 0) + 0.02}, e.mouth_width * 0.55, 0.045);
    fill = mix(fill, kTongue, coverage(tongue, texel));
  }
  c = mix(c, fill, coverage(inside, texel));
  return mix(c, kLip, coverage(std::abs(inside) - 0.009, texel));
}

// Eye: iris and pupil centred on the +x axis, white elsewhere.
Color eye_color(const Dir& d, double texel) {
  if (d.x <= 0) return kWhite;
  const Point p{d.y / d.x, d.z / d.x};
  const double r = std::hypot(p.u, p.v);
  constexpr double kIrisR = 0.5, kPupilR = 0.2;
  const double ang = std::atan2(p.v, p.u);
  const double streaks = 0.5 + 0.5 * std::sin(24 * ang + 3 * std::sin(7 * ang));
  Color iris = mix(kIrisLight, kIris, smoothstep(kPupilR, kIrisR * 0.75, r));
  iris = scale(iris, 0.88 + 0.12 * streaks);
  iris = mix(iris, kLimbus, smoothstep(kIrisR * 0.8, kIrisR, r));
  Color c = mix(kWhite, iris, coverage(r - kIrisR, texel));
  return mix(c, kPupil, coverage(r - kPupilR, texel));
}

// Sleeve: the shirt colour with soft rings around the limb's z axis (constant elevation angle).
Color sleeve_color(const Dir& d, double /*texel*/) {
  const double elevation = std::atan2(d.z, std::hypot(d.x, d.y));
  const double wave = 0.5 + 0.5 * std::cos(2 * kPi * elevation / 0.2);
  return mix(kShirt, kShirtStripe, smoothstep(0.55, 0.8, wave));
}

// Cube texture from images for the listed faces.
TextureAsset cube_texture(std::string name, std::vector<std::pair<Face, Image>> faces,
                          std::string attributes) {
  TextureAsset texture{std::move(name), "cube", {}, std::move(attributes)};
  for (auto& [face, image] : faces) {
    texture.files.emplace_back(std::string(kFaceAttributes[face]), std::move(image));
  }
  return texture;
}

}  // namespace

std::string texture_file_name(const TextureAsset& texture, const std::string& attribute) {
  constexpr std::string_view kPrefix = "file";
  if (attribute == kPrefix) return "tex_" + texture.name + ".png";
  const std::string face =
      attribute.starts_with(kPrefix) ? attribute.substr(kPrefix.size()) : attribute;
  return "tex_" + texture.name + "_" + face + ".png";
}

std::string texture_xml(const TextureAsset& texture) {
  std::string xml = "<texture name=\"" + texture.name + "\" type=\"" + texture.type + "\"";
  for (const auto& [attribute, image] : texture.files) {
    xml += " " + attribute + "=\"" + texture_file_name(texture, attribute) + "\"";
  }
  if (!texture.attributes.empty()) xml += " " + texture.attributes;
  return xml + "/>";
}

std::string material_xml(const MaterialAsset& material) {
  std::string xml = "<material name=\"" + material.name + "\"";
  if (!material.texture.empty()) xml += " texture=\"" + material.texture + "\"";
  if (!material.attributes.empty()) xml += " " + material.attributes;
  return xml + "/>";
}

const std::vector<std::string>& emote_names() {
  static const std::vector<std::string> names = {"default", "happy",     "sad",   "surprised",
                                                 "angry",   "disgusted", "scared"};
  return names;
}

std::string head_texture_name(const std::string& emote) { return "head_" + emote; }

std::vector<TextureAsset> infant_textures(MimoVersion /*version*/) {
  std::vector<TextureAsset> textures;

  // Head: the back, sides and top are the same for every expression; -z stays unset (rgb1).
  const auto base = [](const Dir& d, double texel) { return head_base(d, texel); };
  std::vector<std::pair<Face, Image>> shared;
  for (Face face : {kNegX, kPosY, kNegY, kPosZ}) {
    shared.emplace_back(face, render_face(face, kHeadSize, base));
  }
  const Image face_base = render_face(kPosX, kHeadSize, base);
  const auto& emotes = emote_names();
  for (std::size_t i = 0; i < emotes.size(); ++i) {
    const Expression& expression = kExpressions[i];
    const std::vector<Point> mouth =
        expression.mouth_open > 0 ? mouth_outline(expression) : std::vector<Point>{};
    std::vector<std::pair<Face, Image>> faces = {{kPosX, face_base}};
    paint_face(faces[0].second, kPosX, [&](Color c, const Dir& d, double texel) {
      return paint_expression(c, {d.y / d.x, d.z / d.x}, texel, expression, mouth);
    });
    faces.insert(faces.end(), shared.begin(), shared.end());
    textures.push_back(
        cube_texture(head_texture_name(emotes[i]), std::move(faces), "rgb1=\"0.95 0.8 0.5\""));
  }

  // Eyes: only the +x face, the rest white.
  for (const char* name : {"eye_left", "eye_right"}) {
    textures.push_back(
        cube_texture(name, {{kPosX, render_face(kPosX, kEyeSize, eye_color)}}, "rgb1=\"1 1 1\""));
  }

  // Sleeve: all six faces.
  std::vector<std::pair<Face, Image>> sleeve;
  for (Face face : {kPosX, kNegX, kPosY, kNegY, kPosZ, kNegZ}) {
    sleeve.emplace_back(face, render_face(face, kSleeveSize, sleeve_color));
  }
  textures.push_back(cube_texture("sleeve", std::move(sleeve), ""));
  return textures;
}

std::vector<MaterialAsset> infant_materials(MimoVersion /*version*/) {
  constexpr std::string_view kShirtRgba = "rgba=\"0.1 0.5 0 1\"";
  constexpr std::string_view kPantsRgba = "rgba=\"0.1 0.1 0.6 1\"";
  return {
      {"skin", "", "rgba=\"0.95 0.8 0.5 1\" specular=\"0.15\" shininess=\"0.7\""},
      {"head", head_texture_name("default"), "texuniform=\"true\" specular=\"0\" shininess=\"0\""},
      {"eye_left", "eye_left", "texuniform=\"true\" specular=\"0.4\" shininess=\"0.8\""},
      {"eye_right", "eye_right", "texuniform=\"true\" specular=\"0.4\" shininess=\"0.8\""},
      {"top_up", "", std::string(kShirtRgba)},
      {"top_middle", "", std::string(kShirtRgba)},
      {"top_down", "", std::string(kShirtRgba)},
      {"sleeve", "sleeve", ""},
      {"pants_up", "", std::string(kPantsRgba)},
      {"pants_down", "", std::string(kPantsRgba)},
      {"sock", "", "rgba=\"0.93 0.93 0.9 1\""},
  };
}

}  // namespace cradle::model

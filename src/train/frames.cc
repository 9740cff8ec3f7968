#include "train/frames.h"

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>

#include "core/error.h"

// Differences from the reference, on purpose:
// - Panels render straight at 240x240 where the reference renders 480x480 and keeps every second
//   pixel ([::2, ::2]): a quarter of the work; the picture is the same view, sampled at the centre
//   of each 2x2 block instead of its top-left pixel, and multisampled at 240.
// - The touch map is drawn here, not by matplotlib, with the same projection, marker sizes,
//   colours, opacities and layer order (below), so it also works without a display stack.
//   Contact points are centred on the hip like the sensors and drawn last (see touches()).
// - When touch is off (the reference crashes there) the map shows MIMo's geoms as faint discs.
//
// Cost per frame on the 2-core dev VM (OSMesa llvmpipe; a busy machine, so +-20%):
//   model quality (default):  none ~43 ms, self_touch ~51 ms, hand_regard ~57 ms;
//   {.samples = 0}:           none ~20 ms, self_touch ~28 ms, hand_regard ~26 ms.
// Multisampling costs llvmpipe ~9 ms per render call even for a 16x16 view: in the crib the corner
// goes 32 -> 13 ms and a 240x240 panel 18 -> 9 ms without it, at the price of stair-stepped edges
// on the crib's bars. The touch map itself is ~3 ms (5683 markers).

namespace cradle::train {
namespace {

using Panel = FrameComposer::Panel;

// The reference's touch map is a 600x600 matplotlib figure (6 in at 100 dpi) holding one 3-D
// axes viewed from straight above (elev 90, azim 0), limits hip +-0.75 m on every axis, cropped
// to rows 160-400 and columns 195-435. Matplotlib 3.9 (the kit pins 3.9.4) draws it thus:
// - data -> box units: the box aspect 4:4:3 scaled to norm 1.8295 is 8/7 x 8/7 x 6/7 over 1.5 m;
// - perspective (focal length 1) from an eye 10 box units above the box centre; the screen's
//   right is +y and its up is -x;
// - 2-D view limits [-0.095, 0.09] on both axes (set_top_view), over a square axes of 0.77 x 600
//   px centred in the default subplot (left .125, right .9, bottom .11, top .88).
constexpr double kBoxXY = (8.0 / 7.0) / 1.5;  // box units per metre, x and y
constexpr double kBoxZ = (6.0 / 7.0) / 1.5;   // box units per metre, z
constexpr double kEyeDistance = 10;           // box units from the box centre
constexpr double kViewLow = -0.95 / kEyeDistance, kViewHigh = 0.9 / kEyeDistance;
constexpr double kAxesEdge = 0.77 * 600;                          // px
constexpr double kAxesLeft = (0.125 + (0.775 - 0.77) / 2) * 600;  // px from the left
constexpr double kAxesTop = (1 - 0.88) * 600;                     // px from the top
constexpr double kCropRow = 160, kCropCol = 195;
constexpr double kPxPerView = kAxesEdge / (kViewHigh - kViewLow);
// Where the hip lands in the panel (continuous pixel coordinates, pixel i spans [i, i + 1)).
constexpr double kHipCol = kAxesLeft - kViewLow * kPxPerView - kCropCol;
constexpr double kHipRow = kAxesTop + kViewHigh * kPxPerView - kCropRow;

// Scatter markers: area s in pt^2 (diameter sqrt(s) pt), a 1 pt edge of the face colour drawn
// over the fill (patch.linewidth), 100/72 px per pt.
constexpr double kPxPerPt = 100.0 / 72.0;
constexpr double kEdgeHalf = 0.5 * kPxPerPt;
double face_radius(double area) { return 0.5 * std::sqrt(area) * kPxPerPt; }

constexpr float kBlack[3] = {0, 0, 0};
constexpr float kRed[3] = {1, 0, 0};
constexpr float kYellow[3] = {0.75f, 0.75f, 0};  // matplotlib's "y"
constexpr double kGrayAlpha = 0.15, kGrayArea = 10;
constexpr double kYellowAlpha = 0.8, kYellowArea = 20;
constexpr double kActive = 1e-7;  // force magnitude above which a sensor shows red

// Panel position and scale of a point (dx, dy, dz) metres from the hip.
struct Projected {
  double col, row, scale;  // scale: px per metre at that depth
};
Projected project(double dx, double dy, double dz) {
  const double scale = kPxPerView * kBoxXY / (kEyeDistance - kBoxZ * dz);
  return {kHipCol + scale * dy, kHipRow + scale * dx, scale};
}

// Fraction of a pixel inside a disc edge `x` px beyond its centre (box-filter approximation).
double coverage(double x) { return std::clamp(x + 0.5, 0.0, 1.0); }

int camera(const mjModel* m, const char* name) {
  const int id = mj_name2id(m, mjOBJ_CAMERA, name);
  if (id < 0) throw UserError(std::string("video: the model has no camera named ") + name);
  return id;
}

// The reference's grey (0.2989 R + 0.5870 G + 0.1140 B in float64, truncated by astype(uint8)).
std::uint8_t gray(const std::uint8_t* rgb) {
  return static_cast<std::uint8_t>(0.2989 * rgb[0] + 0.5870 * rgb[1] + 0.1140 * rgb[2]);
}

}  // namespace

FrameComposer::FrameComposer(const envs::BabyBenchEnv& env, senses::RenderQuality quality)
    : corner_cam_(camera(env.model(), "corner")),
      side2_cam_(camera(env.model(), "side2")),
      top_cam_(camera(env.model(), "top")),
      hip_body_(mj_name2id(env.model(), mjOBJ_BODY, "hip")),
      touch_key_(env.key_index(envs::BabyBenchEnv::kTouchKey)),
      quality_(quality),
      renderer_(env.model(), kCorner, kCorner, quality),
      corner_(static_cast<size_t>(kCorner) * kCorner * 3),
      panel_(static_cast<size_t>(kPanel) * kPanel * 3),
      canvas_(static_cast<size_t>(kPanel) * kPanel * 3) {
  const mjModel* m = env.model();
  // The task's panels (the reference's per behaviour).
  const envs::EvaluationPanels panels = env.task().evaluation_panels();
  up_ = panels.up;
  down_ = panels.down;
  if (up_ == Panel::kBinocular) {
    eye_left_cam_ = camera(m, "eye_left");
    eye_right_cam_ = camera(m, "eye_right");
    eye_left_.resize(panel_.size());
    eye_right_.resize(panel_.size());
  }
  if (up_ == Panel::kTouches) {
    if (hip_body_ < 0) throw UserError("video: the model has no body named hip");
    if (!panels.mimo_geoms.empty()) {
      is_hand_.assign(m->ngeom, 0);
      is_mimo_.assign(m->ngeom, 0);
      for (const std::vector<int>& hand : panels.hand_geoms) {
        for (int g : hand) is_hand_[g] = 1;
      }
      for (int g : panels.mimo_geoms) is_mimo_[g] = 1;
    }
    const size_t n = touch_key_ >= 0 ? env.touch()->sensor_count() : m->ngeom;
    sensor_col_.resize(n);
    sensor_row_.resize(n);
    sensor_radius_.resize(n);
    sensor_force_.resize(n);
  }
}

void FrameComposer::corner(const envs::BabyBenchEnv& env, std::span<std::uint8_t> image) {
  renderer_.render(env.model(), env.render_data(), corner_cam_, kCorner, kCorner, image);
}

void FrameComposer::compose(const envs::BabyBenchEnv& env, std::span<std::uint8_t> frame) {
  if (frame.size() != static_cast<size_t>(kHeight) * kWidth * 3) {
    throw std::invalid_argument("FrameComposer: a frame holds 480*720*3 bytes");
  }
  // Corner view on the left.
  corner(env, corner_);
  const size_t corner_row = static_cast<size_t>(kCorner) * 3;
  for (int row = 0; row < kCorner; ++row) {
    std::memcpy(frame.data() + static_cast<size_t>(row) * kWidth * 3,
                corner_.data() + row * corner_row, corner_row);
  }
  // Panels on the right, up then down.
  draw_panel(env, up_);
  place_panel(0, frame);
  draw_panel(env, down_);
  place_panel(kPanel, frame);
}

void FrameComposer::draw_panel(const envs::BabyBenchEnv& env, Panel panel) {
  switch (panel) {
    case Panel::kSide2:
      renderer_.render(env.model(), env.render_data(), side2_cam_, kPanel, kPanel, panel_);
      return;
    case Panel::kTop:
      renderer_.render(env.model(), env.render_data(), top_cam_, kPanel, kPanel, panel_);
      return;
    case Panel::kBinocular:
      binocular(env);
      return;
    case Panel::kTouches:
      touches(env);
      return;
  }
}

void FrameComposer::binocular(const envs::BabyBenchEnv& env) {
  renderer_.render_pair(env.model(), env.render_data(), eye_left_cam_, eye_right_cam_, kPanel,
                        kPanel, eye_left_, eye_right_);
  // Red: the left eye's grey; green and blue: the right eye's.
  for (size_t i = 0; i < panel_.size(); i += 3) {
    const std::uint8_t right = gray(&eye_right_[i]);
    panel_[i] = gray(&eye_left_[i]);
    panel_[i + 1] = right;
    panel_[i + 2] = right;
  }
}

void FrameComposer::touches(const envs::BabyBenchEnv& env) {
  const mjModel* m = env.model();
  const mjData* d = env.data();
  const mjtNum* hip = d->xpos + 3 * hip_body_;
  std::fill(canvas_.begin(), canvas_.end(), 1.0f);
  // Project every sensor (or, without touch, every MIMo geom) and note the strongest force.
  const senses::Touch* touch = touch_key_ >= 0 ? env.touch() : nullptr;
  int points = 0;
  double max_force = 0, gray_top = -INFINITY, red_top = -INFINITY;
  if (touch) {
    const std::span<const float> values = env.observation().f32(touch_key_);
    const int per = touch->values_per_sensor();
    const auto positions = touch->positions();
    const auto bodies = touch->sensor_bodies();
    points = touch->sensor_count();
    for (int s = 0; s < points; ++s) {
      const mjtNum* pos = d->xpos + 3 * bodies[s];
      const mjtNum* mat = d->xmat + 9 * bodies[s];
      const senses::Point3& p = positions[s];
      double rel[3];
      for (int k = 0; k < 3; ++k) {
        rel[k] =
            pos[k] + mat[3 * k] * p[0] + mat[3 * k + 1] * p[1] + mat[3 * k + 2] * p[2] - hip[k];
      }
      double force = 0;
      for (int k = 0; k < per; ++k)
        force += static_cast<double>(values[s * per + k]) * values[s * per + k];
      force = std::sqrt(force);
      const Projected at = project(rel[0], rel[1], rel[2]);
      sensor_col_[s] = at.col;
      sensor_row_[s] = at.row;
      sensor_radius_[s] = face_radius(kGrayArea);
      sensor_force_[s] = force;
      if (force > kActive) {
        max_force = std::max(max_force, force);
        red_top = std::max(red_top, rel[2]);
      } else {
        gray_top = std::max(gray_top, rel[2]);
      }
    }
  } else {
    for (int g = 0; g < static_cast<int>(is_mimo_.size()); ++g) {
      if (!is_mimo_[g]) continue;
      const mjtNum* pos = d->geom_xpos + 3 * g;
      const double dz = pos[2] - hip[2];
      const Projected at = project(pos[0] - hip[0], pos[1] - hip[1], dz);
      sensor_col_[points] = at.col;
      sensor_row_[points] = at.row;
      sensor_radius_[points] = at.scale * m->geom_size[3 * g];  // the geom's first size
      sensor_force_[points] = 0;
      gray_top = std::max(gray_top, dz);
      ++points;
    }
  }
  // Matplotlib draws each scatter call as one collection, the collection whose nearest point is
  // farther first (ties in call order: idle, then active), so idle sensors on MIMo's front
  // usually cover the pressed ones on his back.
  const bool red_first = red_top < gray_top;
  for (int pass = 0; pass < 2; ++pass) {
    const bool red = (pass == 0) == red_first;
    for (int s = 0; s < points; ++s) {
      if ((sensor_force_[s] > kActive) != red) continue;
      if (!red) {
        marker(sensor_col_[s], sensor_row_[s], sensor_radius_[s], kBlack, kGrayAlpha);
        continue;
      }
      // Area 5-10 pt^2 and opacity 0.4-0.5, in proportion to force / strongest force.
      const double f = sensor_force_[s] / max_force;
      marker(sensor_col_[s], sensor_row_[s], face_radius(5 + 5 * f), kRed, 0.4 + 0.1 * f);
    }
  }
  // Hand-MIMo contacts on top. The reference plots them at their world position in the
  // hip-centred axes; with the crib's hip at world (0, 0, 0.30) that is within ~2 px of this
  // place and above every sensor in matplotlib's drawing order.
  for (int i = 0; i < d->ncon && !is_hand_.empty(); ++i) {
    const mjContact& c = d->contact[i];
    if (!(is_hand_[c.geom1] && is_mimo_[c.geom2]) && !(is_hand_[c.geom2] && is_mimo_[c.geom1])) {
      continue;
    }
    const Projected at = project(c.pos[0] - hip[0], c.pos[1] - hip[1], c.pos[2] - hip[2]);
    marker(at.col, at.row, face_radius(kYellowArea), kYellow, kYellowAlpha);
  }
  for (size_t i = 0; i < panel_.size(); ++i) {
    panel_[i] = static_cast<std::uint8_t>(std::lround(canvas_[i] * 255.0f));
  }
}

void FrameComposer::marker(double col, double row, double face, const float* rgb, double alpha) {
  const double outer = face + kEdgeHalf, inner = face - kEdgeHalf;
  // Off the panel (or not a number): nothing to draw.
  if (!(col > -outer && col < kPanel + outer && row > -outer && row < kPanel + outer)) return;
  const int c0 = std::max(0, static_cast<int>(std::floor(col - outer)));
  const int c1 = std::min(kPanel - 1, static_cast<int>(std::floor(col + outer)));
  const int r0 = std::max(0, static_cast<int>(std::floor(row - outer)));
  const int r1 = std::min(kPanel - 1, static_cast<int>(std::floor(row + outer)));
  for (int r = r0; r <= r1; ++r) {
    for (int c = c0; c <= c1; ++c) {
      const double dx = c + 0.5 - col, dy = r + 0.5 - row;
      const double dist = std::sqrt(dx * dx + dy * dy);
      // The fill, then the edge stroke over it (both at the marker's opacity).
      const double fill = alpha * coverage(face - dist);
      const double edge = alpha * (coverage(outer - dist) - coverage(inner - dist));
      if (fill <= 0 && edge <= 0) continue;
      float* px = &canvas_[(static_cast<size_t>(r) * kPanel + c) * 3];
      for (int k = 0; k < 3; ++k) {
        double v = px[k];
        v += (rgb[k] - v) * fill;
        v += (rgb[k] - v) * edge;
        px[k] = static_cast<float>(v);
      }
    }
  }
}

void FrameComposer::place_panel(int top_row, std::span<std::uint8_t> frame) const {
  const size_t bytes = static_cast<size_t>(kPanel) * 3;
  for (int row = 0; row < kPanel; ++row) {
    std::memcpy(frame.data() + (static_cast<size_t>(top_row + row) * kWidth + kCorner) * 3,
                panel_.data() + row * bytes, bytes);
  }
}

}  // namespace cradle::train

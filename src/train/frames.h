// Evaluation video frames in the reference's layout (babybench/utils.py, evaluation_img): a
// 480x480 `corner` view on the left and two 240x240 panels stacked on the right, chosen by the
// task (envs::Task::evaluation_panels). Panels are a camera (`side2`, `top`), the binocular
// anaglyph of the eye cameras, or the self-touch map (MIMo's skin seen from above, active sensors
// in red, hand contacts in yellow).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "envs/babybench.h"
#include "senses/vision.h"

namespace cradle::train {

class FrameComposer {
 public:
  static constexpr int kHeight = 480, kWidth = 720;
  static constexpr int kCorner = 480;  // edge of the corner view (the reference's render_size)
  static constexpr int kPanel = 240;   // edge of each right-column panel

  // What a right-column panel shows (the task says which, Task::evaluation_panels).
  using Panel = envs::EvaluationPanels::View;

  // Looks up the cameras the behaviour's panels need (UserError when the model lacks one) and
  // builds a renderer. Holds no reference to env. The default quality is the model's own, what a
  // person sees in the reference's video; {.samples = 0} is about twice as fast on OSMesa but
  // shows stair-stepped edges (measurements in frames.cc).
  explicit FrameComposer(const envs::BabyBenchEnv& env,
                         senses::RenderQuality quality = senses::RenderQuality::model());

  // Writes the frame for the env's current state: kHeight*kWidth*3 bytes, row 0 at the top.
  void compose(const envs::BabyBenchEnv& env, std::span<std::uint8_t> frame);
  // Only the corner camera, kCorner x kCorner (test-installation's video).
  void corner(const envs::BabyBenchEnv& env, std::span<std::uint8_t> image);

  Panel up() const { return up_; }
  Panel down() const { return down_; }
  const senses::RenderQuality& quality() const { return quality_; }

 private:
  // Draws one panel into panel_.
  void draw_panel(const envs::BabyBenchEnv& env, Panel panel);
  // Red/cyan anaglyph of the grey eye images.
  void binocular(const envs::BabyBenchEnv& env);
  // MIMo's skin from above around the hip, as the reference's matplotlib scatter plot.
  void touches(const envs::BabyBenchEnv& env);
  // Alpha-composites one scatter marker (filled disc plus edge ring) onto canvas_.
  void marker(double col, double row, double face_radius, const float* rgb, double alpha);
  // Copies panel_ into the frame's right column from `top_row`.
  void place_panel(int top_row, std::span<std::uint8_t> frame) const;

  Panel up_, down_;
  int corner_cam_, side2_cam_, top_cam_, eye_left_cam_ = -1, eye_right_cam_ = -1;
  int hip_body_;
  int touch_key_;                        // index of the touch observation (-1 without touch)
  std::vector<char> is_hand_, is_mimo_;  // per geom, from the task's panels (empty: none)
  senses::RenderQuality quality_;
  senses::CameraRenderer renderer_;
  // Preallocated buffers: corner view, one panel, the two eye images, the touch map's float
  // canvas, per-point projections (col, row, grey marker radius in px, force).
  std::vector<std::uint8_t> corner_, panel_, eye_left_, eye_right_;
  std::vector<float> canvas_;
  std::vector<double> sensor_col_, sensor_row_, sensor_radius_, sensor_force_;
};

}  // namespace cradle::train

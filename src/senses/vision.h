// Vision: MuJoCo's own renderer drawing model cameras offscreen in a headless GL context owned by
// the renderer. Images are RGB uint8, row 0 at the top. Rendering reads mjData and never changes
// the simulation state; the shared mjModel is never modified.
#pragma once

#include <mujoco/mujoco.h>

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "core/spaces.h"
#include "senses/gl_context.h"

namespace cradle::senses {

// Render settings that MuJoCo fixes when the GL context is built (mjr_makeContext). They are
// applied to a private copy of the model header, never to the shared model; -1 keeps the model's
// <visual> / geom values.
struct RenderQuality {
  int samples = -1;      // multisamples of the offscreen buffer (offsamples)
  int max_slices = -1;   // at most this tessellation of round geoms (numslices) ...
  int max_stacks = -1;   // ... and (numstacks); the model's value when that is lower
  double min_grid = -1;  // plane grid spacing (a plane's third size) at least this, metres

  // The model's own settings: what the reference renders.
  static RenderQuality model() { return {}; }
  // The eyes' fast path at a given image size: no multisampling; round geoms tessellated so that
  // a sphere filling half the image deviates by under half a pixel (16 slices at 64 px, the
  // model's 28 from 256 px); plane lighting grids of at least 0.2 m. Measurements in vision.cc.
  static RenderQuality fast(int resolution);
};

// Renders fixed or tracking cameras of a shared read-only mjModel into caller-owned RGB buffers.
// Owns its GL context, mjvScene and mjrContext. Each call binds the context to the calling thread
// and unbinds it at the end, so any thread may use the renderer, one at a time. Only geoms that
// can show in a view are drawn (same pixels, far less work: see vision.cc).
class CameraRenderer {
 public:
  // max_width x max_height bounds every later image (for render_pair: both images side by side).
  CameraRenderer(const mjModel* m, int max_width, int max_height,
                 RenderQuality quality = RenderQuality::model());
  ~CameraRenderer();
  CameraRenderer(const CameraRenderer&) = delete;
  CameraRenderer& operator=(const CameraRenderer&) = delete;

  // Renders model camera `camera_id` at w x h into out (w*h*3 bytes).
  void render(const mjModel* m, mjData* d, int camera_id, int w, int h,
              std::span<std::uint8_t> out);
  // Renders two cameras at w x h each in one pass with one read-back (needs 2w <= max_width).
  void render_pair(const mjModel* m, mjData* d, int camera_a, int camera_b, int w, int h,
                   std::span<std::uint8_t> out_a, std::span<std::uint8_t> out_b);

  const GlContext& context() const { return *gl_; }

 private:
  void check(const mjModel* m, int camera_id, int w, int h, std::span<std::uint8_t> out) const;
  // Rebuilds the scene from d for camera_id and keeps its visible geoms in geoms_.
  void update(const mjModel* m, mjData* d, int camera_id);
  // Points the scene at camera_id, keeps the geoms that may show in its view and draws them.
  void draw(const mjModel* m, mjData* d, int camera_id, mjrRect rect);
  // Reads a w x h block (bottom-up) and writes it top-down into outs, split into equal columns.
  void read(int w, int h, std::span<const std::span<std::uint8_t>> outs);

  std::unique_ptr<GlContext> gl_;
  int max_width_, max_height_;
  mjvScene scene_;
  mjrContext con_;
  mjvOption option_;
  mjvCamera camera_;
  bool cull_ = false;                 // no shadows or reflections: off-view geoms cannot show
  std::vector<mjvGeom> geoms_;        // the scene's geoms before per-view culling
  std::vector<std::uint8_t> pixels_;  // read-back buffer, bottom-up rows
};

// The binocular eyes: cameras eye_left and eye_right at resolution^2, both drawn from one scene
// update with one read-back, at RenderQuality::fast(resolution) unless told otherwise.
class Eyes {
 public:
  Eyes(const mjModel* m, int resolution) : Eyes(m, resolution, RenderQuality::fast(resolution)) {}
  Eyes(const mjModel* m, int resolution, RenderQuality quality);

  int resolution() const { return resolution_; }
  // Box uint8 {res, res, 3} on [0, 255]; the same for both eyes.
  Box space() const { return space_for(resolution_); }
  static Box space_for(int resolution);
  // Renders both eyes into left and right (res*res*3 bytes each).
  void render(const mjModel* m, mjData* d, std::span<std::uint8_t> left,
              std::span<std::uint8_t> right);
  CameraRenderer& renderer() { return renderer_; }

  static constexpr const char* kLeftKey = "eye_left";
  static constexpr const char* kRightKey = "eye_right";

 private:
  int resolution_;
  int left_id_, right_id_;
  CameraRenderer renderer_;
};

}  // namespace cradle::senses

#include "senses/vision.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "core/error.h"

// Why this path: both 64x64 eyes of the hand-regard scene (MIMo v2 among the cubes), MuJoCo 2.2.2
// on OSMesa llvmpipe, one core of the 2-core dev VM, medians over a pose (full numbers in the
// vision report; EGL on llvmpipe measures the same):
//   reference pipeline: per eye update + render + read, model quality       ~12 ms
//   both eyes from one scene update, one read-back                          ~12 ms (no gain)
//   + draw only geoms that can show in each view (92 -> 12; same pixels)    ~8 ms
//   + no multisampling                                                      ~3.2 ms
//   + plane lighting grid >= 0.2 m (mean |diff| 0.08/255)                    ~1.7 ms
//   + 16/8 tessellation at 64 px (mean |diff| 0.3/255)                       ~1.0 ms
// Multisampling is the one visible difference from the reference: anti-aliased edges, mean
// |diff| ~1/255, ~3% of pixels off by more than 16. mj_ray alone costs 3.4 ms per 64x64 eye, so a
// CPU ray caster cannot win by a wide margin once it shades and textures like MuJoCo.

namespace cradle::senses {
namespace {

// Room in the scene for every model geom plus MuJoCo's decorations, with a floor like the
// reference viewer's 1000.
int scene_capacity(const mjModel* m) { return std::max(1000, 2 * m->ngeom); }

int camera_id(const mjModel* m, const char* name) {
  const int id = mj_name2id(m, mjOBJ_CAMERA, name);
  if (id < 0) throw UserError(std::string("vision: the model has no camera named ") + name);
  return id;
}

float dot3(const float* a, const float* b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// A view frustum (MuJoCo's mono camera over a viewport) testing bounding spheres.
class Frustum {
 public:
  Frustum(const mjvGLCamera& cam, double aspect) : cam_(cam) {
    const float* f = cam.forward;
    const float* u = cam.up;
    right_[0] = f[1] * u[2] - f[2] * u[1];
    right_[1] = f[2] * u[0] - f[0] * u[2];
    right_[2] = f[0] * u[1] - f[1] * u[0];
    const float half = 0.5f * static_cast<float>(aspect) * (cam.frustum_top - cam.frustum_bottom);
    side(cam.frustum_center + half, 1, planes_[0]);
    side(cam.frustum_center - half, -1, planes_[1]);
    side(cam.frustum_top, 1, planes_[2]);
    side(cam.frustum_bottom, -1, planes_[3]);
  }

  // True when a sphere at pos with radius r lies wholly outside the view.
  bool outside(const float* pos, float r) const {
    const float v[3] = {pos[0] - cam_.pos[0], pos[1] - cam_.pos[1], pos[2] - cam_.pos[2]};
    const float z = dot3(v, cam_.forward);
    if (z < cam_.frustum_near - r || z > cam_.frustum_far + r) return true;
    const float xy[4] = {dot3(v, right_), -dot3(v, right_), dot3(v, cam_.up), -dot3(v, cam_.up)};
    for (int i = 0; i < 4; ++i) {
      if (xy[i] * planes_[i][0] - z * planes_[i][1] > r) return true;
    }
    return false;
  }

 private:
  // Side plane through the eye and the near-plane edge at `edge` (outward sign s): unit normal
  // components along the (signed) side axis and the forward axis.
  void side(float edge, float s, float* plane) const {
    const float n = std::hypot(cam_.frustum_near, edge);
    plane[0] = cam_.frustum_near / n;
    plane[1] = s * edge / n;
  }

  mjvGLCamera cam_;
  float right_[3];
  float planes_[4][2];
};

// Margin on bounding radii against float rounding in Frustum::outside.
constexpr float kCullMargin = 1e-3f;

}  // namespace

RenderQuality RenderQuality::fast(int resolution) {
  // Slices n keep a sphere of radius res/4 pixels within half a pixel: 1 - cos(pi/n) <= 2/res.
  const double step = std::acos(1.0 - 2.0 / std::max(resolution, 8));
  int slices = static_cast<int>(std::ceil(mjPI / step));
  slices = std::max(8, (slices + 3) / 4 * 4);
  return {.samples = 0, .max_slices = slices, .max_stacks = slices / 2, .min_grid = 0.2};
}

CameraRenderer::CameraRenderer(const mjModel* m, int max_width, int max_height,
                               RenderQuality quality)
    : gl_(GlContext::create(max_width, max_height)),
      max_width_(max_width),
      max_height_(max_height),
      geoms_(scene_capacity(m)),
      pixels_(static_cast<size_t>(max_width) * max_height * 3) {
  // MuJoCo sizes the offscreen buffer and builds its display lists from the model; a private
  // header copy (sharing the arrays, plane sizes excepted) carries our size and quality.
  mjModel header = *m;
  mjVisual& vis = header.vis;
  vis.global.offwidth = max_width;
  vis.global.offheight = max_height;
  if (quality.samples >= 0) vis.quality.offsamples = quality.samples;
  if (quality.max_slices > 0) {
    vis.quality.numslices = std::min(vis.quality.numslices, quality.max_slices);
  }
  if (quality.max_stacks > 0) {
    vis.quality.numstacks = std::min(vis.quality.numstacks, quality.max_stacks);
  }
  std::vector<mjtNum> sizes;
  if (quality.min_grid > 0) {
    sizes.assign(m->geom_size, m->geom_size + 3 * m->ngeom);
    for (int i = 0; i < m->ngeom; ++i) {
      if (m->geom_type[i] == mjGEOM_PLANE) {
        sizes[3 * i + 2] = std::max(sizes[3 * i + 2], quality.min_grid);
      }
    }
    header.geom_size = sizes.data();
  }

  const GlScope bound(*gl_);
  mjv_defaultOption(&option_);
  mjv_defaultCamera(&camera_);
  camera_.type = mjCAMERA_FIXED;
  mjv_defaultScene(&scene_);
  mjv_makeScene(m, &scene_, scene_capacity(m));
  mjr_defaultContext(&con_);
  mjr_makeContext(&header, &con_, mjFONTSCALE_50);
  mjr_setBuffer(mjFB_OFFSCREEN, &con_);
  if (con_.currentBuffer != mjFB_OFFSCREEN) {
    mjr_freeContext(&con_);
    mjv_freeScene(&scene_);
    throw UserError("vision: the GL context has no usable offscreen framebuffer");
  }
}

CameraRenderer::~CameraRenderer() {
  // GL objects die with the context anyway; freeing them needs the context bound here.
  try {
    const GlScope bound(*gl_);
    mjr_freeContext(&con_);
  } catch (const UserError&) {
  }
  mjv_freeScene(&scene_);
}

void CameraRenderer::check(const mjModel* m, int camera_id, int w, int h,
                           std::span<std::uint8_t> out) const {
  if (camera_id < 0 || camera_id >= m->ncam) {
    throw std::invalid_argument("CameraRenderer: camera id " + std::to_string(camera_id) +
                                " out of range");
  }
  if (out.size() != static_cast<size_t>(w) * h * 3) {
    throw std::invalid_argument("CameraRenderer: output buffer must hold w*h*3 bytes");
  }
}

void CameraRenderer::update(const mjModel* m, mjData* d, int camera_id) {
  camera_.fixedcamid = camera_id;
  mjv_updateScene(m, d, &option_, nullptr, &camera_, mjCAT_ALL, &scene_);
  // Fully transparent geoms draw nothing (blended, no depth writes): drop them.
  int n = 0;
  bool reflective = false;
  for (int i = 0; i < scene_.ngeom; ++i) {
    const mjvGeom& g = scene_.geoms[i];
    if (g.rgba[3] <= 0) continue;
    reflective |= (g.type == mjGEOM_PLANE || g.type == mjGEOM_BOX) && g.reflectance > 0;
    geoms_[n++] = g;
  }
  scene_.ngeom = n;
  // Shadows and reflections can bring off-view geoms into view; then nothing is culled.
  bool shadows = false;
  if (scene_.flags[mjRND_SHADOW] && con_.shadowFBO) {
    for (int i = 0; i < scene_.nlight; ++i) shadows |= scene_.lights[i].castshadow != 0;
  }
  cull_ = !shadows && !(reflective && scene_.flags[mjRND_REFLECTION]);
}

void CameraRenderer::draw(const mjModel* m, mjData* d, int camera_id, mjrRect rect) {
  camera_.fixedcamid = camera_id;
  mjv_updateCamera(m, d, &camera_, &scene_);
  const int total = scene_.ngeom;
  int n = 0;
  if (cull_) {
    const Frustum view(mjv_averageCamera(&scene_.camera[0], &scene_.camera[1]),
                       static_cast<double>(rect.width) / rect.height);
    for (int i = 0; i < total; ++i) {
      const mjvGeom& g = geoms_[i];
      const bool bounded = g.modelrbound > 0 && g.type != mjGEOM_PLANE;
      if (bounded && view.outside(g.pos, g.modelrbound + kCullMargin)) continue;
      scene_.geoms[n++] = g;
    }
  } else {
    std::copy(geoms_.begin(), geoms_.begin() + total, scene_.geoms);
    n = total;
  }
  scene_.ngeom = n;
  mjr_render(rect, &scene_, &con_);
  scene_.ngeom = total;
}

void CameraRenderer::read(int w, int h, std::span<const std::span<std::uint8_t>> outs) {
  mjr_readPixels(pixels_.data(), nullptr, mjrRect{0, 0, w, h}, &con_);
  const size_t part = static_cast<size_t>(w) * 3 / outs.size();
  for (int row = 0; row < h; ++row) {
    const std::uint8_t* src = pixels_.data() + static_cast<size_t>(h - 1 - row) * w * 3;
    for (size_t i = 0; i < outs.size(); ++i) {
      std::memcpy(outs[i].data() + row * part, src + i * part, part);
    }
  }
}

void CameraRenderer::render(const mjModel* m, mjData* d, int camera_id, int w, int h,
                            std::span<std::uint8_t> out) {
  check(m, camera_id, w, h, out);
  if (w < 1 || h < 1 || w > max_width_ || h > max_height_) {
    throw std::invalid_argument("CameraRenderer: image size beyond the renderer's maximum");
  }
  const GlScope bound(*gl_);
  update(m, d, camera_id);
  draw(m, d, camera_id, mjrRect{0, 0, w, h});
  const std::array<std::span<std::uint8_t>, 1> outs = {out};
  read(w, h, outs);
}

void CameraRenderer::render_pair(const mjModel* m, mjData* d, int camera_a, int camera_b, int w,
                                 int h, std::span<std::uint8_t> out_a,
                                 std::span<std::uint8_t> out_b) {
  check(m, camera_a, w, h, out_a);
  check(m, camera_b, w, h, out_b);
  if (w < 1 || h < 1 || 2 * w > max_width_ || h > max_height_) {
    throw std::invalid_argument("CameraRenderer: image pair beyond the renderer's maximum");
  }
  const GlScope bound(*gl_);
  // One scene update serves both views; only the camera differs.
  update(m, d, camera_a);
  draw(m, d, camera_a, mjrRect{0, 0, w, h});
  draw(m, d, camera_b, mjrRect{w, 0, w, h});
  const std::array<std::span<std::uint8_t>, 2> outs = {out_a, out_b};
  read(2 * w, h, outs);
}

Eyes::Eyes(const mjModel* m, int resolution, RenderQuality quality)
    : resolution_(resolution),
      left_id_(camera_id(m, kLeftKey)),
      right_id_(camera_id(m, kRightKey)),
      renderer_(m, 2 * resolution, resolution, quality) {}

Box Eyes::space_for(int resolution) {
  return Box::uniform({resolution, resolution, 3}, DType::kUInt8, 0, 255);
}

void Eyes::render(const mjModel* m, mjData* d, std::span<std::uint8_t> left,
                  std::span<std::uint8_t> right) {
  renderer_.render_pair(m, d, left_id_, right_id_, resolution_, resolution_, left, right);
}

}  // namespace cradle::senses

// Pictures of SaMI envs: the model's "track" camera drawn offscreen with the project's MuJoCo
// renderer (senses/vision, which needs no infant). Drawn from the env's private model, so crippled
// parts show red and shrunk.
#pragma once

#include <cstdint>
#include <span>

#include "sami/env.h"
#include "senses/vision.h"

namespace cradle::sami {

class Renderer {
 public:
  // Throws UserError when no GL context can be had (see senses/gl_context.h).
  Renderer(const SamiEnv& env, int width, int height);
  int width() const { return width_; }
  int height() const { return height_; }
  // width * height * 3 bytes of RGB, row 0 at the top.
  void render(SamiEnv& env, std::span<std::uint8_t> rgb);

 private:
  int width_, height_, camera_;
  senses::CameraRenderer renderer_;
};

}  // namespace cradle::sami

// Frames of one env of a family that draws (MIMo's sample envs, TeachMyAgent, SaMI) at the
// family's own size and rate, for `cradle evaluate --run --render` and `cradle illustrate
// --render_video`: the apps are the only room that knows every family's renderer.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "core/error.h"
#include "envs/env.h"
#include "envs/mimo/sample_env.h"
#include "envs/sami/sami_env.h"
#include "envs/tma/tma_env.h"
#include "sami/render.h"
#include "tma/physics.h"
#include "tma/render.h"

namespace cradle::apps {

class EnvFilm {
 public:
  explicit EnvFilm(envs::Env& env)
      : mimo_(dynamic_cast<envs::MimoEnv*>(&env)),
        tma_(dynamic_cast<envs::TmaEnvAdapter*>(&env)),
        sami_(dynamic_cast<envs::SamiEnvAdapter*>(&env)) {
    if (mimo_) {
      width_ = height_ = mimo_->render_size();
      fps_ = 1.0 / (mimo_->definition().frame_skip * mimo_->model()->opt.timestep);
    } else if (tma_) {
      width_ = 600, height_ = 400, fps_ = tma::kFps;
    } else if (sami_) {
      width_ = 320, height_ = 240, fps_ = 1.0 / sami_->sami().spec().dt;
      sami_renderer_ = std::make_unique<sami::Renderer>(sami_->sami(), width_, height_);
    } else {
      throw UserError(
          "--render: this env has no renderer (MIMo sample envs, TeachMyAgent and "
          "SaMI envs film)");
    }
    frame_.resize(static_cast<size_t>(width_) * height_ * 3);
  }
  int width() const { return width_; }
  int height() const { return height_; }
  double fps() const { return fps_; }

  std::span<const std::uint8_t> draw() {
    if (mimo_) {
      mimo_->render(frame_);
    } else if (tma_) {
      tma::render(tma_->env(), width_, height_, /*draw_lidars=*/true, frame_);
    } else {
      sami_renderer_->render(sami_->sami(), frame_);
    }
    return frame_;
  }

 private:
  envs::MimoEnv* mimo_;
  envs::TmaEnvAdapter* tma_;
  envs::SamiEnvAdapter* sami_;
  std::unique_ptr<sami::Renderer> sami_renderer_;
  int width_ = 0, height_ = 0;
  double fps_ = 30;
  std::vector<std::uint8_t> frame_;
};

}  // namespace cradle::apps

#include "sami/render.h"

#include <stdexcept>

namespace cradle::sami {

Renderer::Renderer(const SamiEnv& env, int width, int height)
    : width_(width),
      height_(height),
      camera_(mj_name2id(env.model(), mjOBJ_CAMERA, "track")),
      renderer_(env.model(), width, height) {
  if (camera_ < 0) throw std::logic_error("SaMI model without a track camera");
}

void Renderer::render(SamiEnv& env, std::span<std::uint8_t> rgb) {
  renderer_.render(env.model(), env.data(), camera_, width_, height_, rgb);
}

}  // namespace cradle::sami

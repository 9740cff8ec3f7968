// saliency: the reference's example hand-regard reward (examples/intrinsic_handregard_saliency.py).
//
//   r_t = sal(eye_left_t) + sal(eye_right_t),   sal(I) = || L * gray(I) ||_2 / (H W)
//
// gray(I) = 0.2989 R + 0.5870 G + 0.1140 B on the 0..255 values (no rounding); L is the Laplacian
// kernel [[0,-1,0],[-1,4,-1],[0,-1,0]] convolved with scipy.ndimage's "reflect" border (the edge
// pixel repeats: index -1 reads 0, index H reads H-1); ||.||_2 is the Frobenius norm of the H x W
// response. Every uint8 observation of shape {H, W, 3} counts as an eye. Stateless.
#pragma once

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "learn/intrinsic/reward.h"

namespace cradle::learn::intrinsic {

class Saliency final : public IntrinsicReward {
 public:
  explicit Saliency(double scale = 1.0) : IntrinsicReward(scale) {}

  std::string_view name() const override { return "saliency"; }
  // Throws UserError when the vector has no image observation (vision_active off).
  void bind(const VecEnv& env) override;
  void compute(const VecEnv& env, std::span<const double> actions,
               std::span<double> rewards) override;

  // sal() of one row-major RGB image; `gray` is scratch space (resized to height x width).
  static double of(std::span<const std::uint8_t> rgb, int height, int width,
                   std::vector<double>& gray);

 private:
  struct Eye {
    int key, height, width;
  };
  std::vector<Eye> eyes_;
  std::vector<double> gray_;
};

}  // namespace cradle::learn::intrinsic

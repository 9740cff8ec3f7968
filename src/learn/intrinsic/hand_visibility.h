// hand_visibility: hand regard from vision alone, with a skin-colour detector on each eye image
// (no privileged state: only the images MIMo sees).
//
//   r_t = (1 / E) sum_eyes  sum_p w(p) skin(p) / sum_p w(p)
//
// over the E eye images (uint8 {H, W, 3} observations) and their pixels p, where
//   skin(p) = 1 when R + G + B >= min_brightness and the pixel's chromaticity (R, G, B) / (R + G +
//   B)
//             lies within `tolerance` (Euclidean, on the r and g coordinates) of the skin's, else
//             0;
//   w(p)    = exp(-(dx^2 + dy^2) / (2 sigma^2)), dx and dy the pixel centre's offsets from the
//   image
//             centre in units of half the width and half the height.
// So r is in [0, 1]: the centre-weighted fraction of skin pixels, 1 when skin fills both views.
//
// The skin chromaticity is that of MIMo's "skin" material, rgba 0.95 0.8 0.5: (0.4222, 0.3556).
// MuJoCo's white lights scale its colour without changing its chromaticity, and its low specular
// (0.15) adds little white: rendered hand pixels in the hand-regard scene measure (0.420-0.423,
// 0.354-0.357) at brightness 260-500, so the default tolerance 0.03 holds them with room for
// anti-aliased edges.
//
// Limits: it sees skin, not hands. MIMo's forearms share the skin material and count too; the
// detector cannot tell the right hand from the left or a hand from any object of the skin's hue
// (none in the cubes scene's walls, rug and cubes as rendered; other scenes unchecked); pixels
// darker than min_brightness (deep shadow) are missed; and it rewards skin near the image centre,
// not the kit's criterion (the palm within 15 degrees of each eye's optical axis).
#pragma once

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "learn/intrinsic/reward.h"

namespace cradle::learn::intrinsic {

struct HandVisibilityOptions {
  double skin_r = 0.95 / 2.25;  // skin chromaticity r = R / (R + G + B)
  double skin_g = 0.8 / 2.25;   // skin chromaticity g = G / (R + G + B)
  double tolerance = 0.03;      // largest chromaticity distance counted as skin
  int min_brightness = 60;      // smallest R + G + B (0..765) whose chromaticity is trusted
  double sigma = 0.5;           // centre weighting width, in half image sizes
};

class HandVisibility final : public IntrinsicReward {
 public:
  using Options = HandVisibilityOptions;
  explicit HandVisibility(double scale = 1.0, Options options = {})
      : IntrinsicReward(scale), options_(options) {}

  std::string_view name() const override { return "hand_visibility"; }
  // Throws UserError when the vector has no image observation (vision_active off).
  void bind(const VecEnv& env) override;
  void compute(const VecEnv& env, std::span<const double> actions,
               std::span<double> rewards) override;

  // The centre-weighted skin fraction of one row-major RGB image (unscaled).
  double of(std::span<const std::uint8_t> rgb, int height, int width) const;
  // Whether one pixel counts as skin.
  bool skin(std::uint8_t r, std::uint8_t g, std::uint8_t b) const;

 private:
  // Centre weights of an image size, normalised to sum to 1 (cached for the eyes' size).
  const std::vector<double>& weights(int height, int width) const;

  struct Eye {
    int key, height, width;
  };
  Options options_;
  std::vector<Eye> eyes_;
  mutable std::vector<double> weights_;
  mutable int weights_height_ = 0, weights_width_ = 0;
};

}  // namespace cradle::learn::intrinsic

// gaze_alignment: a dense shaping term for hand regard, from the body's geometry (privileged).
//
//   r_t = (1 / 2) sum over the two eyes of (1 - theta_e / 180)^2
//
// theta_e = the angle (deg) between eye e's optical axis and the direction to the nearer palm
// centre after step t (the env's unpublished "right_eye_gaze_angle" / "left_eye_gaze_angle", the
// quantity the hand-regard score thresholds at hand_regard_half_angle). It pays 1 for a palm on
// both axes, 0.84 at 15 deg, 0.25 at 90 deg, so every posture has a gradient towards the eyes'
// axes, which regard_count (sparse, 0 until a palm enters a cone) lacks.
//
// Not an intrinsic motivation: the angle is state the infant does not sense (no vision is read),
// as the MIMo paper's extrinsic reaching rewards. It is an upper-bound baseline for hand regard,
// beside the vision-only hand_visibility. Stateless: an autoreset step's angle is the new
// episode's first, and pays like any other.
#pragma once

#include <array>
#include <span>
#include <string_view>

#include "learn/intrinsic/reward.h"

namespace cradle::learn::intrinsic {

class GazeAlignment final : public IntrinsicReward {
 public:
  explicit GazeAlignment(double scale = 1.0) : IntrinsicReward(scale) {}

  std::string_view name() const override { return "gaze_alignment"; }
  // Throws UserError when the env publishes no gaze angles (behavior: hand_regard).
  void bind(const VecEnv& env) override;
  void compute(const VecEnv& env, std::span<const double> actions,
               std::span<double> rewards) override;

 private:
  std::array<int, 2> slots_ = {-1, -1};  // right eye, left eye
};

}  // namespace cradle::learn::intrinsic

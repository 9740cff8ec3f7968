// regard_count: the hand-regard score's own increments, as a reward.
//
//   r_t = (1 / 2) sum over the two eyes of [either hand in that eye's central field of view in t]
//
// read as this step's increase of the info counters "right_eye_either_hand" and
// "left_eye_either_hand" (the env's hand-regard behaviour decides what "in view" is: the palm
// centre within hand_regard_half_angle of the eye's optical axis). Averaged over an episode, r is
// that episode's either-hand hand-regard score. It is sparse (0 until a palm enters a cone), so it
// is meant beside a dense shaping term such as hand_visibility.
//
// State: the counters' values after the previous step, per env (zero at every episode start).
#pragma once

#include <array>
#include <span>
#include <string_view>
#include <vector>

#include "learn/intrinsic/reward.h"

namespace cradle::learn::intrinsic {

class RegardCount final : public IntrinsicReward {
 public:
  explicit RegardCount(double scale = 1.0) : IntrinsicReward(scale) {}

  std::string_view name() const override { return "regard_count"; }
  // Throws UserError when the env publishes no either-hand counters (behavior: hand_regard).
  void bind(const VecEnv& env) override;
  void reset(const VecEnv& env) override;
  void compute(const VecEnv& env, std::span<const double> actions,
               std::span<double> rewards) override;

 private:
  std::array<int, 2> slots_ = {-1, -1};          // right eye, left eye
  std::vector<std::array<double, 2>> previous_;  // counter values after the previous step
  detail::EpisodeStarts starts_;
};

}  // namespace cradle::learn::intrinsic

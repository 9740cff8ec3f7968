// Hand regard: per step, is each hand within the central field of view of each eye? Measured from
// the eye camera's true optical axis (its -z), to the palm centre, with an optional occlusion test.
#pragma once

#include <mujoco/mujoco.h>

#include <array>

#include "envs/task.h"

namespace cradle::envs {

class HandRegard final : public Task {
 public:
  HandRegard(const mjModel* m, double half_angle_deg, bool occlusion);
  void reset(const mjModel* m, const mjData* d, Info& info) override;
  double after_step(const mjModel* m, const mjData* d, Info& info) override;

  // Angle (deg) between an eye's optical axis and the direction to a hand's palm centre
  // (eye 0 right, 1 left; hand 0 right, 1 left).
  double gaze_angle(const mjData* d, int eye, int hand) const;
  // True if the first thing on the line of sight from the eye to the palm centre is that hand.
  bool visible(const mjModel* m, const mjData* d, int eye, int hand) const;
  // World position of a hand's palm centre.
  std::array<double, 3> palm_centre(const mjData* d, int hand) const;

 private:
  double cos_half_angle_;
  bool occlusion_;
  std::array<int, 2> eye_camera_{};  // eye_right, eye_left
  std::array<int, 2> eye_body_{};
  std::array<int, 2> palm_geom_{};  // first geom of right_hand, left_hand (the palm box)
  std::array<int, 2> hand_body_{};
};

}  // namespace cradle::envs

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
  // Info: steps with each hand in view of each eye ("right_eye_right_hand", "right_eye_left_hand",
  // "left_eye_right_hand", "left_eye_left_hand") and, Cradle's extra, with either hand in view
  // ("right_eye_either_hand", "left_eye_either_hand"); unpublished, for learners only, each eye's
  // angle (deg) to the nearer palm centre at this step ("right_eye_gaze_angle",
  // "left_eye_gaze_angle").
  void declare(Info& info) override;
  void reset(const MimoCore& core, Info& info) override { reset(core.model(), core.data(), info); }
  double after_step(const MimoCore& core, Info& info) override {
    return after_step(core.model(), core.data(), info);
  }
  // The same on any model and data (the tests' inline models).
  void reset(const mjModel* m, const mjData* d, Info& info);
  double after_step(const mjModel* m, const mjData* d, Info& info);
  // The mean over the four eye-hand pairs of the fraction of steps in view.
  double score(const Info& info, int steps) const override;
  // The binocular view above the top camera, and the four gaze-hand angles per step against the
  // central field of view.
  EvaluationPanels evaluation_panels() const override;
  void trace(const mjData* d, std::span<double> values) const override;

  // Angle (deg) between an eye's optical axis and the direction to a hand's palm centre
  // (eye 0 right, 1 left; hand 0 right, 1 left).
  double gaze_angle(const mjData* d, int eye, int hand) const;
  // True if the first thing on the line of sight from the eye to the palm centre is that hand.
  bool visible(const mjModel* m, const mjData* d, int eye, int hand) const;
  // World position of a hand's palm centre.
  std::array<double, 3> palm_centre(const mjData* d, int hand) const;

 private:
  double half_angle_deg_, cos_half_angle_;
  bool occlusion_;
  std::array<int, 2> eye_camera_{};  // eye_right, eye_left
  std::array<int, 2> eye_body_{};
  std::array<int, 2> palm_geom_{};  // first geom of right_hand, left_hand (the palm box)
  std::array<int, 2> hand_body_{};
  std::array<int, 4> pair_slot_{};    // eye-major: right eye (right, left hand), left eye (...)
  std::array<int, 2> either_slot_{};  // right eye, left eye
  std::array<int, 2> angle_slot_{};   // right eye, left eye
};

}  // namespace cradle::envs

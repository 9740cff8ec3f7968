#include "envs/hand_regard.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace cradle::envs {

HandRegard::HandRegard(const mjModel* m, double half_angle_deg, bool occlusion)
    : half_angle_deg_(half_angle_deg),
      cos_half_angle_(std::cos(half_angle_deg * std::numbers::pi / 180)),
      occlusion_(occlusion) {
  const char* cameras[2] = {"eye_right", "eye_left"};
  const char* hands[2] = {"right_hand", "left_hand"};
  for (int i = 0; i < 2; ++i) {
    eye_camera_[i] = mj_name2id(m, mjOBJ_CAMERA, cameras[i]);
    hand_body_[i] = mj_name2id(m, mjOBJ_BODY, hands[i]);
    if (eye_camera_[i] < 0 || hand_body_[i] < 0) {
      throw std::runtime_error("hand regard needs MIMo's eye cameras and hands");
    }
    eye_body_[i] = m->cam_bodyid[eye_camera_[i]];
    palm_geom_[i] = m->body_geomadr[hand_body_[i]];
  }
}

void HandRegard::declare(Info& info) {
  const char* eyes[2] = {"right_eye_", "left_eye_"};
  const char* hands[2] = {"right_hand", "left_hand"};
  for (int eye = 0; eye < 2; ++eye) {
    for (int hand = 0; hand < 2; ++hand) {
      pair_slot_[2 * eye + hand] =
          info.declare(std::string(eyes[eye]) + hands[hand], InfoType::kInt);
    }
  }
  for (int eye = 0; eye < 2; ++eye) {
    either_slot_[eye] = info.declare(std::string(eyes[eye]) + "either_hand", InfoType::kInt);
    angle_slot_[eye] = info.declare(std::string(eyes[eye]) + "gaze_angle", InfoType::kReal,
                                    /*published=*/false);
  }
}

void HandRegard::reset(const mjModel*, const mjData* d, Info& info) {
  for (int slot : pair_slot_) info.set(slot, 0);
  for (int slot : either_slot_) info.set(slot, 0);
  for (int eye = 0; eye < 2; ++eye) {
    info.set(angle_slot_[eye], std::min(gaze_angle(d, eye, 0), gaze_angle(d, eye, 1)));
  }
}

double HandRegard::score(const Info& info, int steps) const {
  if (steps == 0) return 0;
  double sum = 0;
  for (int slot : pair_slot_) sum += info.number(slot);
  return sum / (4.0 * steps);
}

EvaluationPanels HandRegard::evaluation_panels() const {
  return {.up = EvaluationPanels::View::kBinocular,
          .trace = EvaluationPanels::Trace{
              .key = "gaze_angle",
              .title = "Gaze-hand angle (evaluation episode 0)",
              .y_label = "angle (°)",
              .file = "gaze_hand_angle.png",
              .labels = {"right eye - right hand", "right eye - left hand", "left eye - right hand",
                         "left eye - left hand"},
              .y_range = {0.0, 180.0},
              .threshold = std::pair{half_angle_deg_, "central field of view"}}};
}

void HandRegard::trace(const mjData* d, std::span<double> values) const {
  // Eye-major, as the info's pairs: right eye (right, left hand), then left eye.
  for (int eye = 0; eye < 2; ++eye) {
    for (int hand = 0; hand < 2; ++hand) values[2 * eye + hand] = gaze_angle(d, eye, hand);
  }
}

std::array<double, 3> HandRegard::palm_centre(const mjData* d, int hand) const {
  const mjtNum* p = d->geom_xpos + 3 * palm_geom_[hand];
  return {p[0], p[1], p[2]};
}

double HandRegard::gaze_angle(const mjData* d, int eye, int hand) const {
  const mjtNum* eye_pos = d->cam_xpos + 3 * eye_camera_[eye];
  const mjtNum* eye_rot = d->cam_xmat + 9 * eye_camera_[eye];
  const auto palm = palm_centre(d, hand);
  // A camera looks along its -z axis: minus the third column of its rotation.
  const double axis[3] = {-eye_rot[2], -eye_rot[5], -eye_rot[8]};
  const double to_hand[3] = {palm[0] - eye_pos[0], palm[1] - eye_pos[1], palm[2] - eye_pos[2]};
  const double norm =
      std::sqrt(to_hand[0] * to_hand[0] + to_hand[1] * to_hand[1] + to_hand[2] * to_hand[2]);
  if (norm == 0) return 180;
  const double c = (axis[0] * to_hand[0] + axis[1] * to_hand[1] + axis[2] * to_hand[2]) / norm;
  return std::acos(std::clamp(c, -1.0, 1.0)) * 180 / std::numbers::pi;
}

bool HandRegard::visible(const mjModel* m, const mjData* d, int eye, int hand) const {
  const mjtNum* eye_pos = d->cam_xpos + 3 * eye_camera_[eye];
  const auto palm = palm_centre(d, hand);
  mjtNum start[3] = {eye_pos[0], eye_pos[1], eye_pos[2]};
  mjtNum ray[3] = {palm[0] - start[0], palm[1] - start[1], palm[2] - start[2]};
  int hit = -1;
  // Ray from the eye (its own eyeball excluded) towards the palm centre; the ray is not
  // normalised, so a hit distance below 1 lies before the palm centre.
  const mjtNum distance = mj_ray(m, d, start, ray, nullptr, 1, eye_body_[eye], &hit);
  if (hit < 0 || distance > 1) return true;
  // Visible if what is hit first belongs to the hand (palm or fingers).
  for (int b = m->geom_bodyid[hit]; b > 0; b = m->body_parentid[b]) {
    if (b == hand_body_[hand]) return true;
  }
  return false;
}

double HandRegard::after_step(const mjModel* m, const mjData* d, Info& info) {
  for (int eye = 0; eye < 2; ++eye) {
    bool either = false;
    double nearest = 180;
    for (int hand = 0; hand < 2; ++hand) {
      const double degrees = gaze_angle(d, eye, hand);
      nearest = std::min(nearest, degrees);
      bool in_view = std::cos(degrees * std::numbers::pi / 180) > cos_half_angle_;
      if (in_view && occlusion_) in_view = visible(m, d, eye, hand);
      info.add(pair_slot_[2 * eye + hand], in_view);
      either = either || in_view;
    }
    info.add(either_slot_[eye], either);
    info.set(angle_slot_[eye], nearest);
  }
  return 0;
}

}  // namespace cradle::envs

#include "learn/intrinsic/gaze_alignment.h"

#include "core/error.h"

namespace cradle::learn::intrinsic {

void GazeAlignment::bind(const VecEnv& env) {
  const char* angles[2] = {"right_eye_gaze_angle", "left_eye_gaze_angle"};
  for (int eye = 0; eye < 2; ++eye) {
    slots_[eye] = env.num_envs() > 0 ? env.info(0).find(angles[eye]) : -1;
  }
  if (env.num_envs() > 0 && (slots_[0] < 0 || slots_[1] < 0)) {
    throw UserError(
        "gaze_alignment needs the hand-regard gaze angles right_eye_gaze_angle/"
        "left_eye_gaze_angle (behavior: hand_regard)");
  }
}

void GazeAlignment::compute(const VecEnv& env, std::span<const double>, std::span<double> rewards) {
  if (env.num_envs() > 0 && slots_[0] < 0) bind(env);
  for (int i = 0; i < env.num_envs(); ++i) {
    const envs::Info& info = env.info(i);
    double alignment = 0;
    for (int slot : slots_) {
      const double closeness = 1 - info.number(slot) / 180;
      alignment += closeness * closeness;
    }
    rewards[i] += scale() * alignment / 2;
  }
}

}  // namespace cradle::learn::intrinsic

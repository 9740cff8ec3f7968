#include "learn/intrinsic/touch_count.h"

#include "core/error.h"

namespace cradle::learn::intrinsic {

double TouchCount::of(std::span<const float> touch, double threshold) {
  if (touch.empty()) return 0;
  long active = 0;
  for (float value : touch) active += value > threshold;
  return static_cast<double>(active) / static_cast<double>(touch.size());
}

void TouchCount::bind(const VecEnv& env) {
  touch_key_ = detail::key_index(env, "touch");
  if (touch_key_ < 0) throw UserError("intrinsic reward touch_count needs touch (touch_active)");
}

void TouchCount::compute(const VecEnv& env, std::span<const double>, std::span<double> rewards) {
  if (touch_key_ < 0) bind(env);
  for (int i = 0; i < env.num_envs(); ++i) {
    rewards[i] += scale() * of(env.observation(i).f32(touch_key_), options_.threshold);
  }
}

}  // namespace cradle::learn::intrinsic

#include "learn/intrinsic/regard_count.h"

#include "core/error.h"

namespace cradle::learn::intrinsic {

void RegardCount::bind(const VecEnv& env) {
  const int n = env.num_envs();
  const char* counters[2] = {"right_eye_either_hand", "left_eye_either_hand"};
  for (int eye = 0; eye < 2; ++eye) slots_[eye] = n > 0 ? env.info(0).find(counters[eye]) : -1;
  if (n > 0 && (slots_[0] < 0 || slots_[1] < 0)) {
    throw UserError(
        "regard_count needs the hand-regard info counters right_eye_either_hand/"
        "left_eye_either_hand (behavior: hand_regard)");
  }
  previous_.assign(n, {0, 0});
  starts_.assign(n, true);
}

void RegardCount::reset(const VecEnv& env) {
  if (static_cast<int>(previous_.size()) != env.num_envs()) bind(env);
  for (int i = 0; i < env.num_envs(); ++i) {
    for (int eye = 0; eye < 2; ++eye) {
      previous_[env.env_id(i)][eye] = env.info(i).number(slots_[eye]);
    }
  }
  starts_.assign(env.num_envs(), false);
}

void RegardCount::compute(const VecEnv& env, std::span<const double>, std::span<double> rewards) {
  if (previous_.empty()) bind(env);
  for (int i = 0; i < env.num_envs(); ++i) {
    const int id = env.env_id(i);
    const envs::Info& info = env.info(i);
    double in_view = 0;
    for (int eye = 0; eye < 2; ++eye) {
      const double now = info.number(slots_[eye]);
      // An autoreset step starts a new episode (its counters restart from the reset's values):
      // no transition, no reward.
      if (!starts_[id] && now >= previous_[id][eye]) in_view += now - previous_[id][eye];
      previous_[id][eye] = now;
    }
    rewards[i] += scale() * in_view / 2;
  }
  starts_.record_flags(env);
}

}  // namespace cradle::learn::intrinsic

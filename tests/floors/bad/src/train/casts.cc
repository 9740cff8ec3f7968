// A training file that casts to a concrete env: the floor check must refuse it (ctest
// floor_check_refuses_a_cast_outside_envs); only envs/, apps/ and python/ may.
#include "envs/env.h"

namespace cradle::train {
bool is_self_touch(const envs::Env& env) {
  return dynamic_cast<const envs::BabyBenchEnv*>(&env) != nullptr;
}
}  // namespace cradle::train

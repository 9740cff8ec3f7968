#include "learn/learner.h"

#include "core/error.h"
#include "learn/a2c.h"
#include "learn/ppo.h"

namespace cradle::learn {

std::unique_ptr<Learner> make_learner(std::string_view algorithm, VecEnv& env,
                                      const LearnerOptions& options) {
  if (algorithm == "ppo") return make_ppo(env, options);
  if (algorithm == "a2c") return make_a2c(env, options);
  throw UserError("unknown algorithm '" + std::string(algorithm) + "' (expected ppo or a2c)");
}

}  // namespace cradle::learn

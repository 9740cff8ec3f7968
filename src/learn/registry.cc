#include "learn/registry.h"

#include "core/error.h"
#include "learn/a2c.h"
#include "learn/ddpg.h"
#include "learn/ppo.h"
#include "learn/sac.h"
#include "learn/td3.h"

namespace cradle::learn {

std::unique_ptr<Learner> make_learner(std::string_view algorithm, VecEnv& env,
                                      const LearnerOptions& options) {
  if (algorithm == "ppo") return make_ppo(env, options);
  if (algorithm == "a2c") return make_a2c(env, options);
  if (algorithm == "sac") return make_sac(env, options);
  if (algorithm == "td3") return make_td3(env, options);
  if (algorithm == "ddpg") return make_ddpg(env, options);
  throw UserError("unknown algorithm '" + std::string(algorithm) +
                  "' (expected ppo, a2c, sac, td3 or ddpg)");
}

}  // namespace cradle::learn

#include "learn/registry.h"

#include "core/error.h"
#include "learn/a2c.h"
#include "learn/ddpg.h"
#include "learn/meta/sami_learner.h"
#include "learn/ppo.h"
#include "learn/sac.h"
#include "learn/td3.h"

namespace cradle::learn {

const std::vector<std::string>& algorithm_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out{"ppo", "a2c", "sac", "td3", "ddpg"};
    for (const std::string_view name : meta::sami_learner_names()) out.emplace_back(name);
    return out;
  }();
  return names;
}

std::vector<std::string> extra_report_keys(std::string_view algorithm) {
  if (!meta::sami_method(algorithm).empty()) return {"sance_loss", "sance_weight"};
  return {};
}

std::unique_ptr<Learner> make_learner(std::string_view algorithm, VecEnv& env,
                                      const LearnerOptions& options) {
  if (algorithm == "ppo") return make_ppo(env, options);
  if (algorithm == "a2c") return make_a2c(env, options);
  if (algorithm == "sac") return make_sac(env, options);
  if (algorithm == "td3") return make_td3(env, options);
  if (algorithm == "ddpg") return make_ddpg(env, options);
  if (!meta::sami_method(algorithm).empty()) {
    return meta::make_sami_learner(algorithm, env, options);
  }
  // "ppo, a2c, ... or saccm_all".
  const std::vector<std::string>& names = algorithm_names();
  std::string expected;
  for (size_t k = 0; k < names.size(); ++k) {
    expected += (k == 0 ? "" : k + 1 == names.size() ? " or " : ", ") + names[k];
  }
  throw UserError("unknown algorithm '" + std::string(algorithm) + "' (expected " + expected + ")");
}

}  // namespace cradle::learn

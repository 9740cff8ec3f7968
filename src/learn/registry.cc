#include "learn/registry.h"

#include "core/error.h"
#include "core/text.h"
#include "learn/a2c.h"
#include "learn/ddpg.h"
#include "learn/meta/sami_learner.h"
#include "learn/ppo.h"
#include "learn/sac.h"
#include "learn/td3.h"

namespace cradle::learn {

namespace {

using Factory = std::unique_ptr<Learner> (*)(VecEnv&, const LearnerOptions&);

struct Algorithm {
  std::string_view name;
  Factory make;
  AlgorithmTraits traits;
};

// Every algorithm, in the order to list them; SaMI's methods follow (meta::sami_learner_names).
constexpr Algorithm kAlgorithms[] = {
    {"ppo", make_ppo, {.data_parallel = true, .async_collection = true}},
    {"a2c", make_a2c, {.data_parallel = true, .async_collection = true}},
    {"sac", make_sac, {.data_parallel = true}},
    {"td3", make_td3, {.data_parallel = true}},
    {"ddpg", make_ddpg, {.data_parallel = true}},
};

[[noreturn]] void unknown(std::string_view algorithm) {
  throw UserError("unknown algorithm '" + std::string(algorithm) + "' (expected " +
                  algorithm_list() + ")");
}

}  // namespace

const std::vector<std::string>& algorithm_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const Algorithm& a : kAlgorithms) out.emplace_back(a.name);
    for (const std::string_view name : meta::sami_learner_names()) out.emplace_back(name);
    return out;
  }();
  return names;
}

AlgorithmTraits algorithm_traits(std::string_view algorithm) {
  for (const Algorithm& a : kAlgorithms) {
    if (a.name == algorithm) return a.traits;
  }
  // SaMI's learners train data-parallel and collect lock-step.
  if (!meta::sami_method(algorithm).empty()) return {.data_parallel = true};
  unknown(algorithm);
}

std::string algorithm_list() { return listed(algorithm_names()); }

std::string algorithms_with(bool AlgorithmTraits::*trait, std::string_view last) {
  std::vector<std::string> names;
  for (const std::string& name : algorithm_names()) {
    if (algorithm_traits(name).*trait) names.push_back(name);
  }
  return listed(names, last);
}

std::vector<std::string> extra_report_keys(std::string_view algorithm) {
  if (!meta::sami_method(algorithm).empty()) return {"sance_loss", "sance_weight"};
  return {};
}

std::unique_ptr<Learner> make_learner(std::string_view algorithm, VecEnv& env,
                                      const LearnerOptions& options) {
  for (const Algorithm& a : kAlgorithms) {
    if (a.name == algorithm) return a.make(env, options);
  }
  if (!meta::sami_method(algorithm).empty()) {
    return meta::make_sami_learner(algorithm, env, options);
  }
  unknown(algorithm);
}

}  // namespace cradle::learn

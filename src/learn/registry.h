// The learners by name: the one file that knows every algorithm (learner.h is only the
// interface each implements).
#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "learn/learner.h"

namespace cradle::learn {

// Every algorithm make_learner builds, in the order to list them: "ppo", "a2c", "sac", "td3",
// "ddpg", then SaMI's context learners "tesac", "ccm", "satesac", "saccm", "saccm_all"
// (learn/meta/sami_learner.h).
const std::vector<std::string>& algorithm_names();
// Every algorithm, for messages: "ppo, a2c, ... or saccm_all".
std::string algorithm_list();

// Builds a learner by name (one of algorithm_names()). Throws UserError for an unknown algorithm
// or hyperparameter, a bad value, or an env the learner cannot handle.
std::unique_ptr<Learner> make_learner(std::string_view algorithm, VecEnv& env,
                                      const LearnerOptions& options);

// What an algorithm can do besides training on one process's vector of envs.
struct AlgorithmTraits {
  // --distributed: gradients averaged over ranks (LearnerOptions::sync)
  bool data_parallel = false;
  bool async_collection = false;  // --async-batch: collects from an AsyncVecEnv in batches
};
// UserError naming the algorithms for an unknown name.
AlgorithmTraits algorithm_traits(std::string_view algorithm);
// The algorithms that have `trait`, in listing order, for messages: "ppo, a2c or sac" (`last` is
// the word before the last name).
std::string algorithms_with(bool AlgorithmTraits::*trait, std::string_view last = "or");

// The report keys (TrainStats::losses) an algorithm adds to those every run logs, in order: a
// run's progress.csv gives each a losses/<key> column (SaMI's methods: "sance_loss",
// "sance_weight"; the others none).
std::vector<std::string> extra_report_keys(std::string_view algorithm);

}  // namespace cradle::learn

// The learners by name: the one file that knows every algorithm (learner.h is only the
// interface each implements).
#pragma once

#include <memory>
#include <string_view>

#include "learn/learner.h"

namespace cradle::learn {

// Builds a learner by name ("ppo", "a2c", "sac", "td3", "ddpg"). Throws UserError for an unknown
// algorithm or hyperparameter, a bad value, or an env the learner cannot handle.
std::unique_ptr<Learner> make_learner(std::string_view algorithm, VecEnv& env,
                                      const LearnerOptions& options);

}  // namespace cradle::learn

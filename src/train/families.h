// What each env family brings to the one run (train::train) beyond its envs: the settings its
// learners train with and the curriculum a teacher gets without a task-space file. One entry per
// family of the env registry (envs/registry.h), asked by the family's name; the run knows no
// family by name. A new family adds its entry in families.cc.
#pragma once

#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "envs/registry.h"
#include "train/task_space.h"

namespace cradle::train {

struct Family {
  // Hyperparameters for `algorithm` on `env`, which the run applies under the user's (SaMI's
  // learners: whole episodes as trajectories; Panda's batch sizes). Null: none.
  std::map<std::string, std::string> (*presets)(const envs::EnvSpec& env,
                                                const std::string& algorithm) = nullptr;
  // The curriculum of `--teacher NAME` without a task-space file: the env's declared task
  // parameters (never empty here) with the family's facts (return bounds, easy region, what the
  // teacher hears).
  CurriculumSpec (*curriculum)(const envs::EnvSpec& env) = nullptr;
  // What the family's own tools write in a run folder, by shell pattern (fnmatch): SaMI's
  // evaluations, and an earlier version's checkpoint and progress files. A folder holding one
  // holds a run, and --overwrite removes them with it.
  std::vector<std::string> outputs;
};

// The family of that name (babybench, mimo, tma, sami); UserError naming them for another.
const Family& family(std::string_view name);

}  // namespace cradle::train

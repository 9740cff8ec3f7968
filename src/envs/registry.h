// Every env of every family by one id: the one list of env names that the CLI (`cradle envs`,
// `cradle train --env`), the run path and Python (`cradle.make`) ask.
//
// Ids, one scheme for the four families:
//   babybench/<config>            a bundled BabyBench config (configs/config_<config>.yml); any
//                                 path to a BabyBench YAML is accepted too (not listed)
//   mimo/<task>                   a MIMo sample env (reach, standup, selfbody, catch, bench,
//                                 bench-v2, showroom); the reference's names (MIMoReach-v0) are
//                                 aliases
//   tma/<env>:<embodiment>        a TeachMyAgent env (stump-tracks, parkour) with one body
//   sami/<Env>[:<split>]          a SaMI env on a split (train, moderate, extreme; train when left
//                                 out) or on the task sets of a YAML file (not listed)
// A factory compiles what its envs share once (the scene, the model, the CPPN); a vector builds
// every env from one factory.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "envs/env.h"

namespace cradle::envs {

struct EnvSpec {
  std::string id;             // "mimo/reach", "tma/parkour:fish", "sami/CrippleAnt:moderate", ...
  std::string family;         // "babybench", "mimo", "tma" or "sami"
  std::string summary;        // one line, for listings
  int max_episode_steps = 0;  // truncation (0: none)
  std::vector<TaskParameter> parameters;
  std::vector<std::string> aliases;  // other names of the same env (the reference's)
  // Envs a vector needs to hold each of the family's training task sets once (SaMI: one sub-env
  // per task set, as SaMI's DummyVecEnv); 1 elsewhere.
  int natural_envs = 1;
  // BabyBench: the config file the env is built from ("" for the documented defaults), so that a
  // run can train it as a config (with its training log, evaluation and intrinsic rewards).
  std::string config;
};

// Constructor options by name, as text (TeachMyAgent's body options such as motors_torque,
// MIMo's actuation, SaMI's contact_forces); each family refuses a name it does not take.
using EnvOptions = std::map<std::string, std::string, std::less<>>;

// Builds the envs of one id. `index` is the env's place in a vector (SaMI: env i draws its
// tasks from training set i mod the number of sets); -1 makes a lone env (SaMI: every set of the
// split). The env is reset with `seed`.
using EnvMaker = std::function<std::unique_ptr<Env>(int index, std::uint64_t seed)>;

// The parts of an id "family/name[:variant]" ("tma/parkour:fish": tma, parkour, fish); a part the
// id lacks is empty.
struct EnvIdParts {
  std::string family, name, variant;
};
EnvIdParts split_env_id(std::string_view id);

// Every listed id, by family (babybench, mimo, tma, sami) then name.
const std::vector<EnvSpec>& env_specs();
// The spec of an id, an alias or an unlisted form (a YAML path). Throws UserError for an unknown
// id, naming the closest listed ids.
EnvSpec env_spec(std::string_view id);
// A factory for the id's envs, with what they share built now. Throws UserError for an unknown
// id or an option the env does not take.
EnvMaker env_maker(std::string_view id, const EnvOptions& options = {});
// One env of the id (a lone env: index -1), reset with `seed`.
std::unique_ptr<Env> make_env(std::string_view id, std::uint64_t seed = 0,
                              const EnvOptions& options = {});

// The listed ids closest to `id` (edit distance), best first, at most `count`.
std::vector<std::string> close_env_ids(std::string_view id, int count = 3);

}  // namespace cradle::envs

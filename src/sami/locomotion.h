// The MuJoCo locomotion envs of SaMI (tma_sami.md §7.1, sami_models.md §0-2): Half-Cheetah, Ant,
// Hopper, Walker, SlimHumanoid, HumanoidStandup and their crippled variants, one class driven by a
// per-env table of rewards, observations, scaling rules and crippling rules.
#pragma once

#include <memory>

#include "sami/env.h"

namespace cradle::sami {

std::unique_ptr<SamiEnv> make_locomotion(Spec spec, ModelPtr model, std::vector<TaskSet> sets,
                                         std::uint64_t seed, Options options);

}  // namespace cradle::sami

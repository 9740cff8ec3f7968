// Panda push (tma_sami.md §7.2, sami_models.md §3): end-effector displacement control through
// damped least-squares IK, a finger command, dense reward, success at 5 cm, skill labels.
#pragma once

#include <memory>

#include "sami/env.h"

namespace cradle::sami {

std::unique_ptr<SamiEnv> make_panda(Spec spec, ModelPtr model, std::vector<TaskSet> sets,
                                    std::uint64_t seed);

// The per-step skill label of a state (after mj_forward or mj_step), from the cube height and its
// contacts with the table and each finger.
Skill panda_skill(const mjModel* m, const mjData* d);

}  // namespace cradle::sami

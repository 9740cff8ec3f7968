// Panda push (tma_sami.md §7.2, sami_models.md §3): end-effector displacement control through
// damped least-squares IK, a finger command, dense reward, success at 5 cm, skill labels.
#pragma once

#include <memory>
#include <vector>

#include "sami/env.h"

namespace cradle::sami {

std::unique_ptr<SamiEnv> make_panda(Spec spec, ModelPtr model, std::vector<TaskSet> sets,
                                    std::uint64_t seed);

// Damped least-squares IK of the grasp target (position plus the pointing-down orientation) over
// the 7 arm joints, starting from given joints; works on its own scratch mjData.
class PandaIk {
 public:
  explicit PandaIk(const mjModel* m);
  // Arm joint targets (7) for `target`, starting from the full qpos; the scratch data then holds
  // the kinematics of the solution.
  void solve(const mjModel* m, const mjtNum* qpos, const mjtNum target[3], mjtNum out[7]);
  const mjData* scratch() const { return data_.get(); }
  int site() const { return site_; }
  int arm_qpos(int k) const { return arm_qpos_[k]; }
  int arm_dof(int k) const { return arm_dof_[k]; }

 private:
  std::unique_ptr<mjData, void (*)(mjData*)> data_;
  std::vector<mjtNum> jac_;
  int site_ = 0, arm_qpos_[7] = {}, arm_dof_[7] = {};
  double range_[7][2] = {};
};

// Bullet's combined lateral friction of a contact: the product of the two bodies' coefficients,
// clipped at 10 (btManifoldResult). MuJoCo would take the larger one.
double bullet_friction(double a, double b);

// The per-step skill label of a state (after mj_forward or mj_step), from the cube height and its
// contacts with the table and each finger.
Skill panda_skill(const mjModel* m, const mjData* d);

}  // namespace cradle::sami

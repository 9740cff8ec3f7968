#include "sami/panda.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace cradle::sami {
namespace {

constexpr int kArm = 7;
constexpr double kNeutral[kArm] = {0, 0.41, 0, -1.85, 0, 2.26, 0.79};
constexpr double kHalfRange = 0.15;  // cube and goal x, y in [-0.15, 0.15]
constexpr double kCubeHalf = 0.02;   // cube half size and resting height
constexpr double kSuccess = 0.05;    // distance threshold
constexpr double kEeStep = 0.05;     // metres per unit action
constexpr double kFingerMax = 0.04;  // finger joint range [0, 0.04]
constexpr double kFingerStep = 0.2;  // width change per unit action
constexpr int kIkIterations = 30;
constexpr double kIkDamping = 1e-2;  // damped least squares lambda
constexpr double kServoRate = 50;    // PyBullet: kp * erp / dt = 0.1 * 1 / 0.002 per second
// Gripper pointing down: 180 degrees about world x (wxyz).
constexpr mjtNum kDown[4] = {0, 1, 0, 0};

int id_of(const mjModel* m, mjtObj type, const char* name) {
  const int id = mj_name2id(m, type, name);
  if (id < 0) throw std::logic_error(std::string("Panda model has no ") + name);
  return id;
}

}  // namespace

double bullet_friction(double a, double b) { return std::min(a * b, 10.0); }

namespace {}  // namespace

PandaIk::PandaIk(const mjModel* m) : data_(mj_makeData(m), mj_deleteData), jac_(6 * m->nv) {
  site_ = id_of(m, mjOBJ_SITE, "grasptarget");
  for (int k = 0; k < kArm; ++k) {
    const int j = id_of(m, mjOBJ_JOINT, ("joint" + std::to_string(k + 1)).c_str());
    arm_qpos_[k] = m->jnt_qposadr[j];
    arm_dof_[k] = m->jnt_dofadr[j];
    range_[k][0] = m->jnt_range[2 * j], range_[k][1] = m->jnt_range[2 * j + 1];
  }
}

void PandaIk::solve(const mjModel* m, const mjtNum* qpos, const mjtNum target[3], mjtNum out[7]) {
  mjData* ik = data_.get();
  mju_copy(ik->qpos, qpos, m->nq);
  for (int it = 0; it < kIkIterations; ++it) {
    mj_kinematics(m, ik);
    mj_comPos(m, ik);
    // Error: position, and the rotation from the current to the target orientation (world).
    mjtNum e[6], quat[4], local[3];
    mju_sub3(e, target, ik->site_xpos + 3 * site_);
    mju_mat2Quat(quat, ik->site_xmat + 9 * site_);
    mju_subQuat(local, kDown, quat);
    mju_rotVecMat(e + 3, local, ik->site_xmat + 9 * site_);
    if (mju_norm3(e) < 1e-5 && mju_norm3(e + 3) < 1e-4) break;
    mj_jacSite(m, ik, jac_.data(), jac_.data() + 3 * m->nv, site_);
    // J is 6 x 7 over the arm dofs; dq = J^T (J J^T + lambda^2 I)^-1 e.
    mjtNum j[6][kArm], a[36], y[6];
    for (int r = 0; r < 6; ++r) {
      for (int k = 0; k < kArm; ++k) j[r][k] = jac_[r * m->nv + arm_dof_[k]];
    }
    for (int r = 0; r < 6; ++r) {
      for (int c = 0; c < 6; ++c) {
        a[6 * r + c] = mju_dot(j[r], j[c], kArm) + (r == c ? kIkDamping * kIkDamping : 0);
      }
    }
    mju_cholFactor(a, 6, 0);
    mju_cholSolve(y, a, e, 6);
    for (int k = 0; k < kArm; ++k) {
      mjtNum dq = 0;
      for (int r = 0; r < 6; ++r) dq += j[r][k] * y[r];
      mjtNum& q = ik->qpos[arm_qpos_[k]];
      q = std::clamp(q + dq, range_[k][0], range_[k][1]);
    }
  }
  mj_kinematics(m, ik);
  for (int k = 0; k < kArm; ++k) out[k] = ik->qpos[arm_qpos_[k]];
}

Skill panda_skill(const mjModel* m, const mjData* d) {
  const int cube = mj_name2id(m, mjOBJ_GEOM, "object");
  const int table = mj_name2id(m, mjOBJ_GEOM, "table");
  const int left = mj_name2id(m, mjOBJ_GEOM, "leftfinger");
  const int right = mj_name2id(m, mjOBJ_GEOM, "rightfinger");
  bool on_table = false, touch_left = false, touch_right = false;
  for (int i = 0; i < d->ncon; ++i) {
    const int a = d->contact[i].geom1, b = d->contact[i].geom2;
    if (a != cube && b != cube) continue;
    const int other = a == cube ? b : a;
    on_table |= other == table;
    touch_left |= other == left;
    touch_right |= other == right;
  }
  const double z = d->geom_xpos[3 * cube + 2];
  if (z > 0.021 && !on_table && touch_left && touch_right) return Skill::kPickAndPlace;
  if (z > 0.021) return Skill::kRoll;
  if (z > 0.019 && z < 0.21) return Skill::kPush;
  return Skill::kDown;
}

namespace {

class PandaPush final : public SamiEnv {
 public:
  PandaPush(Spec spec, ModelPtr model, std::vector<TaskSet> sets, std::uint64_t seed)
      : SamiEnv(std::move(spec), std::move(model), std::move(sets), seed), ik_(shared_.get()) {
    const mjModel* m = shared_.get();
    site_ = ik_.site();
    cube_body_ = id_of(m, mjOBJ_BODY, "object");
    table_ = id_of(m, mjOBJ_GEOM, "table");
    target_mocap_ = m->body_mocapid[id_of(m, mjOBJ_BODY, "target")];
    const int cube_joint = id_of(m, mjOBJ_JOINT, "object");
    cube_qpos_ = m->jnt_qposadr[cube_joint];
    cube_dof_ = m->jnt_dofadr[cube_joint];
    for (int k = 0; k < kArm; ++k) {
      servo_qpos_[k] = ik_.arm_qpos(k);
      servo_dof_[k] = ik_.arm_dof(k);
    }
    for (int f = 0; f < 2; ++f) {
      const int j = id_of(m, mjOBJ_JOINT, f == 0 ? "finger_joint1" : "finger_joint2");
      servo_qpos_[kArm + f] = m->jnt_qposadr[j];
      servo_dof_[kArm + f] = m->jnt_dofadr[j];
    }
  }

  void reset_episode(std::optional<std::uint64_t> seed) override {
    const TaskSet& set = begin_reset(seed);
    const mjModel* m = &model_;
    mjData* d = data_.get();
    // Task cell: table friction and cube mass with its box inertia. The geom frictions are
    // Bullet's per-body coefficients; every contact pair of the table takes their product.
    const auto& cell = set.cells[rng_.next() % set.cells.size()];
    info_.friction = cell[0];
    info_.mass = cell[1];
    geom_friction_[3 * table_] = cell[0];
    for (int p = 0; p < m->npair; ++p) {
      const int a = m->pair_geom1[p], b = m->pair_geom2[p];
      if (a != table_ && b != table_) continue;
      pair_friction_[5 * p] = pair_friction_[5 * p + 1] =
          bullet_friction(geom_friction_[3 * a], geom_friction_[3 * b]);
    }
    body_mass_[cube_body_] = cell[1];
    for (int i = 0; i < 3; ++i) body_inertia_[3 * cube_body_ + i] = cell[1] * 2.667e-4;
    // Robot at the neutral pose, fingers closed, at rest; goal then cube on the table.
    for (int k = 0; k < kArm; ++k) d->qpos[servo_qpos_[k]] = kNeutral[k];
    goal_[0] = rng_.uniform(-kHalfRange, kHalfRange);
    goal_[1] = rng_.uniform(-kHalfRange, kHalfRange);
    goal_[2] = kCubeHalf;
    mju_copy3(d->mocap_pos + 3 * target_mocap_, goal_);
    mjtNum* cube = d->qpos + cube_qpos_;
    cube[0] = rng_.uniform(-kHalfRange, kHalfRange);
    cube[1] = rng_.uniform(-kHalfRange, kHalfRange);
    cube[2] = kCubeHalf;
    cube[3] = 1, cube[4] = cube[5] = cube[6] = 0;
    for (int k = 0; k < kArm; ++k) target_[k] = kNeutral[k];
    target_[kArm] = target_[kArm + 1] = 0;
    mj_forward(m, d);
    finish(false);
  }

  StepResult step_episode(std::span<const double> action) override {
    check_action(action);
    const mjModel* m = &model_;
    mjData* d = data_.get();
    double a[4];
    for (int i = 0; i < 4; ++i) a[i] = std::clamp(action[i], -1.0, 1.0);
    // Arm: IK towards the measured end effector plus the commanded displacement.
    mjtNum target[3];
    for (int i = 0; i < 3; ++i) target[i] = d->site_xpos[3 * site_ + i] + kEeStep * a[i];
    target[2] = std::max(target[2], 0.0);
    ik_.solve(m, d->qpos, target, target_);
    // Fingers: each takes half of the commanded width, kept within the joint range (PyBullet's
    // hard limits; MuJoCo's soft ones would yield to the 170 N motors).
    const double width =
        d->qpos[servo_qpos_[kArm]] + d->qpos[servo_qpos_[kArm + 1]] + kFingerStep * a[3];
    target_[kArm] = target_[kArm + 1] = std::clamp(width / 2, 0.0, kFingerMax);
    // PyBullet's motor law each substep: target velocity 50 (q* - q), force-limited.
    for (int k = 0; k < spec_.frame_skip; ++k) {
      for (int i = 0; i < kArm + 2; ++i) {
        d->ctrl[i] = kServoRate * (target_[i] - d->qpos[servo_qpos_[i]]);
        // Gravity and Coriolis held outside the force limit: PyBullet's motor is a velocity
        // constraint that gravity cannot sag, a finite MuJoCo kv would.
        d->qfrc_applied[servo_dof_[i]] = d->qfrc_bias[servo_dof_[i]];
      }
      mj_step(m, d);
    }
    info_.steps++;
    const double distance = finish(true);
    StepResult out;
    out.reward = -static_cast<float>(distance);
    out.terminated = info_.is_success;
    out.truncated = info_.steps >= spec_.horizon;
    return out;
  }

 private:
  // Observation, success and skill labels of the current state; returns the goal distance.
  double finish(bool stepped) {
    const mjModel* m = &model_;
    const mjData* d = data_.get();
    double* o = obs_.data();
    mjtNum velocity[6];
    mj_objectVelocity(m, d, mjOBJ_SITE, site_, velocity, 0);
    o = std::copy_n(d->site_xpos + 3 * site_, 3, o);
    o = std::copy_n(velocity + 3, 3, o);
    *o++ = d->qpos[servo_qpos_[kArm]] + d->qpos[servo_qpos_[kArm + 1]];
    const mjtNum* cube = d->qpos + cube_qpos_;
    o = std::copy_n(cube, 3, o);
    // PyBullet's Euler angles (roll, pitch, yaw) of the cube quaternion (w, x, y, z).
    const mjtNum w = cube[3], x = cube[4], y = cube[5], z = cube[6];
    *o++ = std::atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y));
    *o++ = std::asin(std::clamp(2 * (w * y - z * x), -1.0, 1.0));
    *o++ = std::atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z));
    // Linear velocity (world) and angular velocity rotated from the body to the world frame.
    o = std::copy_n(d->qvel + cube_dof_, 3, o);
    mjtNum omega[3];
    mju_rotVecMat(omega, d->qvel + cube_dof_ + 3, d->xmat + 9 * cube_body_);
    o = std::copy_n(omega, 3, o);
    o = std::copy_n(cube, 3, o);
    std::copy_n(goal_, 3, o);
    // Float32 distance, as the reference computes it.
    float dist2 = 0;
    for (int i = 0; i < 3; ++i) {
      const float diff = static_cast<float>(cube[i]) - static_cast<float>(goal_[i]);
      dist2 += diff * diff;
    }
    const double distance = std::sqrt(dist2);
    info_.is_success = distance < kSuccess;
    if (stepped) {
      info_.skill = panda_skill(m, d);
      Skill& e = info_.episode_skill;
      if (info_.skill == Skill::kPickAndPlace) {
        e = Skill::kPickAndPlace;
      } else if (info_.skill == Skill::kRoll && e != Skill::kPickAndPlace) {
        e = Skill::kRoll;
      } else if (e == Skill::kNone) {
        e = Skill::kPush;
      }
    }
    return distance;
  }

  PandaIk ik_;
  int site_ = 0, cube_body_ = 0, table_ = 0, target_mocap_ = 0, cube_qpos_ = 0, cube_dof_ = 0;
  int servo_qpos_[kArm + 2] = {}, servo_dof_[kArm + 2] = {};  // arm joints, then the fingers
  mjtNum target_[kArm + 2] = {};                              // joint targets of the servos
  mjtNum goal_[3] = {};
};

}  // namespace

std::unique_ptr<SamiEnv> make_panda(Spec spec, ModelPtr model, std::vector<TaskSet> sets,
                                    std::uint64_t seed) {
  return std::make_unique<PandaPush>(std::move(spec), std::move(model), std::move(sets), seed);
}

}  // namespace cradle::sami

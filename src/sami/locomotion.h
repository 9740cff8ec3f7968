// The MuJoCo locomotion mechanics SaMI's locomotion envs share (tma_sami.md §7.1, sami_models.md
// §0-2): the episode start (reset noise, hidden parameters drawn and written after the first
// forward), the step (float32 action times the crippling mask, frame skip, forward velocity) and
// the cost sums in NumPy's order. What differs between the envs is a LocomotionDef, written in
// each env's file (sami/envs/<env>.cc): its reward, observation, mass and damping rule, crippling
// and noise. None of SaMI's locomotion envs terminates: episodes end at the horizon.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "sami/env.h"

namespace cradle::sami {

// Where the forward term's x comes from: root x (qpos[0]) or the torso body's xpos as mj_step
// leaves it (computed at the start of the last substep, not recomputed: gym's get_body_com).
enum class Forward { kRootX, kTorsoXpos };

// What a reward reads after a step.
struct LocomotionStep {
  const mjModel* model = nullptr;  // the env's model (its hidden parameters applied)
  const mjData* data = nullptr;
  double velocity = 0;  // forward velocity over the step
  // The root x-velocity of the state the step starts from, as the float32 observation holds it.
  double start_vx = 0;
  double ctrl = 0;  // ctrl_cost * sum(a^2), computed as the reference does (LocomotionDef)
  // Sum of squares of cfrc_ext in NumPy's order, each entry clipped to [-1, 1] first when `clip`.
  // cfrc_ext stays zero unless Options::contact_forces (as in the published runs).
  double cfrc_squares(bool clip) const;
};

// The actuators and geoms one crippled unit (a joint; Ant: a leg) disables; -1: none.
struct CrippleParts {
  std::array<int, 2> actuators{-1, -1}, geoms{-1, -1};
};

// What differs between the locomotion envs.
struct LocomotionDef {
  // The reference's reward term by term, in its order of operations.
  double (*reward)(const LocomotionStep& step) = nullptr;
  // Writes the observation (spec obs_size values); velocity is 0 after a reset.
  void (*observe)(const mjModel* m, const mjData* d, double velocity, double* out) = nullptr;
  // Writes the mass and damping factors into `own` (the env's private arrays, restored to the
  // shared model's values) from `shared` (sami_models.md §2).
  void (*scale)(const mjModel* shared, mjModel* own, double mass, double damping) = nullptr;
  Forward forward = Forward::kRootX;
  // Info's x_velocity: the start's root x-velocity (SlimHumanoid's reward pays for it) instead of
  // the step's forward velocity.
  bool info_start_vx = false;
  // The parts of crippled unit k (null: the env cannot be crippled); `shrink`: its capsules get
  // half radius and half length as well.
  CrippleParts (*cripple)(int unit) = nullptr;
  bool shrink = false;
  double ctrl_cost = 0;  // weight of ||a||^2
  // ||a||^2 in float32, as NumPy computes it on the reference's float32 action; the crippled
  // envs multiply the action by a float64 mask first, so theirs is in float64.
  bool ctrl_cost_f32 = false;
  bool uniform_pos = false;  // reset noise on qpos: uniform(+-pos_noise), else normal
  bool uniform_vel = false;  // same for qvel
  double pos_noise = 0, vel_noise = 0;
};

// The scaling rules most envs share: every body's mass and every dof's damping times the factor,
// or the masses only (the crippled envs).
void scale_mass_and_damping(const mjModel* shared, mjModel* own, double mass, double damping);
void scale_mass(const mjModel* shared, mjModel* own, double mass, double damping);

std::unique_ptr<SamiEnv> make_locomotion(Spec spec, ModelPtr model, std::vector<TaskSet> sets,
                                         std::uint64_t seed, Options options,
                                         const LocomotionDef& def);

}  // namespace cradle::sami

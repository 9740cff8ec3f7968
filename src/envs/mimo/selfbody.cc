// MIMoSelfBody-v0 (mimo_core.md §6.3): MIMo sits, everything but his right arm locked, and learns
// to touch a randomly chosen part of his own body with that arm. The goal is a one-hot vector over
// the candidate parts. Reward: 500 on touching the target (success, ends the episode); else minus
// the distance from the fingers to the target while the hand touches something, or -1.
#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "envs/mimo/sample_env.h"

namespace cradle::envs {
namespace {

constexpr double kTouchReward = 500;
constexpr double kIdleReward = -1;
constexpr int kSettleSteps = 25;  // zero-action physics steps after locking the pose

// Touch spacings (m), in the reference's order: the first kTargets bodies are the candidate
// targets; the last two (left forearm, right mitten) are the touching parts.
constexpr std::pair<const char*, double> kSkin[] = {
    {"left_foot", 0.05},
    {"right_foot", 0.05},
    {"left_lower_leg", 0.1},
    {"right_lower_leg", 0.1},
    {"left_upper_leg", 0.1},
    {"right_upper_leg", 0.1},
    {"hip", 0.1},
    {"lower_body", 0.1},
    {"upper_body", 0.1},
    {"head", 0.1},
    {"left_upper_arm", 0.01},
    {"left_lower_arm", 0.01},
    {"right_fingers", 0.01},
};
constexpr int kTargets = static_cast<int>(std::size(kSkin)) - 2;
// The right arm, whose contact with the target counts as touching it.
constexpr const char* kRightArm[] = {"right_upper_arm", "right_lower_arm", "right_hand",
                                     "right_fingers"};

// The sitting pose (rad) every joint but the right arm's is locked at.
constexpr std::pair<const char*, double> kSitting[] = {
    {"hip_lean1", 0.039088},
    {"hip_rot1", 0.113112},
    {"hip_bend1", 0.5323},
    {"hip_lean2", 0},
    {"hip_rot2", 0},
    {"hip_bend2", 0.5323},
    {"head_swivel", 0},
    {"head_tilt", 0},
    {"head_tilt_side", 0},
    {"left_eye_horizontal", 0},
    {"left_eye_vertical", 0},
    {"left_eye_torsional", 0},
    {"right_eye_horizontal", 0},
    {"right_eye_vertical", 0},
    {"right_eye_torsional", 0},
    {"left_shoulder_horizontal", 0.683242},
    {"left_shoulder_ad_ab", 0.3747},
    {"left_shoulder_rotation", -0.62714},
    {"left_elbow", -0.756016},
    {"left_hand1", 0.28278},
    {"left_hand2", 0},
    {"left_hand3", 0},
    {"left_fingers", -0.461583},
    {"right_hip1", -1.51997},
    {"right_hip2", -0.397578},
    {"right_hip3", 0.0976615},
    {"right_knee", -1.85479},
    {"right_foot1", -0.585865},
    {"right_foot2", -0.358165},
    {"right_foot3", 0},
    {"right_toes", 0},
    {"left_hip1", -1.23961},
    {"left_hip2", -0.8901},
    {"left_hip3", 0.7156},
    {"left_knee", -2.531},
    {"left_foot1", -0.63562},
    {"left_foot2", 0.5411},
    {"left_foot3", 0.366514},
    {"left_toes", 0.24424},
};

class SelfBody final : public SampleTask {
 public:
  explicit SelfBody(const MimoCore& core) : fingers_(body_id(core.model(), "right_fingers")) {
    const mjModel* m = core.model();
    for (int k = 0; k < static_cast<int>(std::size(kSkin)); ++k) {
      skin_[k] = body_id(m, kSkin[k].first);
    }
    arm_.assign(m->nbody, 0);
    for (const char* body : kRightArm) arm_[body_id(m, body)] = 1;
  }

  void initialize_episode(MimoCore& core, Rng& rng, std::span<double> goal) override {
    // A target drawn first (one-hot goal), then the start state at rest.
    target_ = static_cast<int>(rng.uniform() * kTargets);
    std::ranges::fill(goal, 0.0);
    goal[target_] = 1;
    mju_zero(core.data()->qvel, core.model()->nv);
    mj_forward(core.model(), core.data());
  }

  void observe(const MimoCore& core, std::span<double>, std::span<double> achieved) override {
    for (size_t k = 0; k < achieved.size(); ++k) achieved[k] = arm_touches(core, skin_[k]) ? 1 : 0;
  }

  double after_step(const MimoCore& core, Info& info) override {
    const bool success = arm_touches(core, skin_[target_]);
    set_outcome(info, success, false);
    if (success) return kTouchReward;
    if (feels(core, skin_[kTargets]) || feels(core, skin_[kTargets + 1])) {
      const mjData* d = core.data();
      double v[3];
      mju_sub3(v, d->xpos + 3 * fingers_, d->xpos + 3 * skin_[target_]);
      return -mju_norm3(v);
    }
    return kIdleReward;
  }

 private:
  // Whether the right arm is in contact with body `b` (normal force above the touch threshold).
  bool arm_touches(const MimoCore& core, int b) const {
    const mjModel* m = core.model();
    const mjData* d = core.data();
    for (int i = 0; i < d->ncon; ++i) {
      const mjContact& c = d->contact[i];
      const int b1 = m->geom_bodyid[c.geom1], b2 = m->geom_bodyid[c.geom2];
      if (!((b1 == b && arm_[b2]) || (b2 == b && arm_[b1]))) continue;
      mjtNum force[6];
      mj_contactForce(m, d, i, force);
      if (std::abs(force[0]) >= 1e-9) return true;
    }
    return false;
  }

  // Whether any touch sensor of body b reads a force.
  bool feels(const MimoCore& core, int b) const {
    const senses::Touch& skin = *core.touch();
    const int first = skin.first_sensor(b);
    if (first < 0) return false;
    const int n = skin.sensors_on_body(b) * skin.values_per_sensor();
    const std::span<const float> values = core.observation()
                                              .f32(core.key_index(MimoCore::kTouchKey))
                                              .subspan(first * skin.values_per_sensor(), n);
    return std::ranges::any_of(values, [](float v) { return v != 0; });
  }

  int fingers_;
  std::array<int, std::size(kSkin)> skin_{};
  std::vector<char> arm_;
  int target_ = 0;
};

}  // namespace

std::vector<std::string> selfbody_targets() {
  std::vector<std::string> names;
  for (int k = 0; k < kTargets; ++k) names.emplace_back(kSkin[k].first);
  return names;
}

SampleDefinition selfbody_definition() {
  SampleDefinition def{.name = "MIMoSelfBody-v0",
                       .max_episode_steps = 500,
                       .frame_skip = 1,
                       .goals_in_observation = true,
                       .goal_size = kTargets};
  for (const auto& [body, spacing] : kSkin) def.touch[body] = spacing;
  def.camera_lookat = {0.1, 0, 0.2};
  def.camera_distance = 0.9;
  def.camera_azimuth = 160;
  def.camera_elevation = -25;
  def.scene = [](const SampleOptions&) {
    scene::Composition c;
    c.worlds = {sample_floor()};
    c.placement = {{0.0579584, -0.00157173, 0.0566738},
                   {0.892294, -0.0284863, -0.450353, -0.0135029}};
    c.emit.actuators =
        std::set<std::string>{"right_shoulder_horizontal", "right_shoulder_abduction",
                              "right_shoulder_internal",   "right_elbow",
                              "right_wrist_rotation",      "right_wrist_flexion",
                              "right_wrist_ulnar",         "right_fingers"};
    for (const auto& [joint, angle] : kSitting) c.emit.lock_angles[joint] = angle;
    scene::WorldFragments task;
    task.equality = "<weld body1=\"mimo_location\"/>\n";
    c.worlds.push_back(std::move(task));
    return c;
  };
  def.initial_state = [](const mjModel* m, mjData* d) {
    // Start in the locked pose and let it settle under zero action; that is the start state.
    for (const auto& [joint, angle] : kSitting) {
      d->qpos[qpos_address(m, std::string("robot:") + joint)] = angle;
    }
    mj_forward(m, d);
    for (int i = 0; i < kSettleSteps; ++i) mj_step(m, d);
    mju_zero(d->qvel, m->nv);
  };
  def.make = [](MimoCore& core, const SampleOptions&) -> std::unique_ptr<Task> {
    return std::make_unique<SelfBody>(core);
  };
  return def;
}

}  // namespace cradle::envs

// MIMoCatch-v0 (mimo_core.md §6.4): the five-fingered MIMo holds his right palm open under a
// falling ball (random size, mass and drop point) and must catch it and hold it for one second.
// Muscle actuation by default; head and eyes follow the ball. Reward per step: +1 while touching
// the ball, -40 x muscle cost, -100 on dropping it (failure), +100 on holding it for 100 steps
// (success); both end the episode. Reset options (a curriculum's parameters) fix what the reference
// draws: the drop point's offset ball_dx, ball_dy, ball_dz, ball_radius and ball_mass; ball_speed
// throws the ball down at that speed when it is released.
#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <utility>

#include "envs/mimo/sample_env.h"
#include "model/infant.h"

namespace cradle::envs {
namespace {

constexpr int kHoldSteps = 100;  // env steps of continuous contact (1 s) for success
constexpr double kContactReward = 1, kCostWeight = 40, kEndReward = 100;
constexpr double kDropHeight = 0.1;    // m below the hand: dropped
constexpr double kDropDistance = 0.5;  // m from the hand: bounced away
constexpr int kSettleSteps = 50;       // raw physics steps without gravity at reset
constexpr double kAimError = 0.005;    // m per axis, position_inaccurate
constexpr double kMinForce = 1e-9;     // N, the touch threshold

// Ball start: XML position, and half-widths of its uniform offset.
constexpr double kBallPos[3] = {0.24, -0.04, 0.8};
constexpr double kBallJitter[3] = {0.01, 0.01, 0.08};
constexpr double kRadius[2] = {0.005, 0.025}, kMass[2] = {0.05, 0.5};
// What reset options may set: offsets (m), downward speed (m/s), radius (m), mass (kg).
constexpr double kOptionOffset = 0.3, kOptionSpeed = 5;
constexpr double kOptionRadius[2] = {0.005, 0.05}, kOptionMass[2] = {0.01, 2};
// Jitter: gains per action dimension, redrawn every 10 to 50 steps.
constexpr double kGain[2] = {0.8, 1.2};
constexpr int kGainSteps[2] = {10, 51};

// Right arm held out, palm up; thumb tucked (rad).
constexpr std::pair<const char*, double> kPinned[] = {
    {"right_shoulder_horizontal", 1.7},
    {"right_shoulder_ad_ab", 0.8},
    {"right_shoulder_rotation", -1.6},
    {"right_elbow", -0.4},
    {"right_th_swivel", 0},
    {"right_th_adduction", -0.9},
    {"right_th_pivot", 0},
    {"right_th_middle", 0.4},
    {"right_th_distal", 0.3},
};

// palm_up: the wrist rotation's pin of MIMo's first catch scene (rad); it turns the palm up.
constexpr const char* kWristRotation = "right_hand1";
constexpr double kPalmUpAngle = -1.4;

// Touch spacings (m) of the right arm.
const std::map<std::string, double> kSkin = {
    {"right_upper_arm", 0.024},    {"right_lower_arm", 0.024}, {"right_hand", 0.007},
    {"right_ffdistal", 0.002},     {"right_mfdistal", 0.002},  {"right_rfdistal", 0.002},
    {"right_lfdistal", 0.002},     {"right_thdistal", 0.002},  {"right_ffmiddle", 0.004},
    {"right_mfmiddle", 0.004},     {"right_rfmiddle", 0.004},  {"right_lfmiddle", 0.004},
    {"right_thhub", 0.004},        {"right_ffknuckle", 0.004}, {"right_mfknuckle", 0.004},
    {"right_rfknuckle", 0.004},    {"right_lfknuckle", 0.004}, {"right_thbase", 0.004},
    {"right_lfmetacarpal", 0.007},
};

class Catch final : public SampleTask {
 public:
  Catch(MimoCore& core, const SampleOptions& options)
      : options_(options),
        model_(core.own_model()),  // ball size, mass and gravity change per episode
        tracking_(model_),
        hand_(body_id(model_, "right_hand")),
        ball_body_(body_id(model_, "target")),
        ball_geom_(mj_name2id(model_, mjOBJ_GEOM, "target")),
        ball_qpos_(qpos_address(model_, "target_joint")),
        ball_dof_(model_->jnt_dofadr[mj_name2id(model_, mjOBJ_JOINT, "target_joint")]),
        wrist_qpos_(qpos_address(model_, std::string("robot:") + kWristRotation)),
        zero_(core.action_space().size(), 0.0),
        gains_(core.action_space().size(), 1.0),
        jittered_(core.action_space().size()),
        low_(core.action_space().low),
        high_(core.action_space().high) {
    sensing_.assign(model_->nbody, 0);
    for (const auto& [body, spacing] : kSkin) sensing_[body_id(model_, body)] = 1;
  }

  void initialize_episode(MimoCore& core, Rng& rng, std::span<double>) override {
    mjModel* m = model_;
    mjData* d = core.data();
    // A new ball: drop point, radius and mass (solid sphere inertia).
    // (Every value is drawn, so the stream stays the same; a set option replaces it.)
    for (int i = 0; i < 3; ++i) {
      const double drawn = rng.uniform(-kBallJitter[i], kBallJitter[i]);
      d->qpos[ball_qpos_ + i] = kBallPos[i] + set_[i].value_or(drawn);
    }
    mju_zero(d->qvel + ball_dof_, 6);
    if (options_.palm_up) d->qpos[wrist_qpos_] = kPalmUpAngle;
    radius_ = set_[kRadiusSlot].value_or(rng.uniform(kRadius[0], kRadius[1]));
    const double mass = set_[kMassSlot].value_or(rng.uniform(kMass[0], kMass[1]));
    m->geom_size[3 * ball_geom_] = radius_;
    m->geom_rbound[ball_geom_] = radius_;
    m->body_mass[ball_body_] = mass;
    for (int i = 0; i < 3; ++i)
      m->body_inertia[3 * ball_body_ + i] = 0.4 * mass * radius_ * radius_;
    // mj_setConst recomputes the mass-dependent constants from qpos0; the state is kept.
    sim::State state;
    core.sim().save(state);
    mj_setConst(m, d);
    core.sim().restore(state);
    for (int i = 0; i < 3; ++i) aim_error_[i] = 0;
    if (options_.position_inaccurate) {
      for (double& e : aim_error_) e = rng.uniform(-kAimError, kAimError);
    }
    gain_steps_ = 0;

    // Let the hand settle without gravity, ball hovering; then the ball starts to fall.
    const double gravity = m->opt.gravity[2];
    m->opt.gravity[2] = 0;
    core.sim().actuation().reset(d);
    core.sim().actuation().apply(zero_, d);
    for (int i = 0; i < kSettleSteps; ++i) core.raw_step();
    m->opt.gravity[2] = gravity;
    d->qvel[ball_dof_ + 2] = -set_[kSpeedSlot].value_or(0);  // released (or thrown) downward
    held_.fill(0);
    after_physics(core);
    mj_forward(m, d);
  }

  std::span<const double> before_step(std::span<const double> action, Rng& rng) override {
    if (!options_.jitter) return action;
    if (--gain_steps_ <= 0) {
      gain_steps_ = static_cast<int>(rng.uniform(kGainSteps[0], kGainSteps[1]));
      for (double& g : gains_) g = rng.uniform(kGain[0], kGain[1]);
    }
    for (size_t k = 0; k < jittered_.size(); ++k) {
      jittered_[k] = std::clamp(action[k] * gains_[k], low_[k], high_[k]);
    }
    return jittered_;
  }

  void set_reset_options(const ResetOptions& options) override {
    const TaskOption known[] = {
        {"ball_dx", -kOptionOffset, kOptionOffset, &set_[0]},
        {"ball_dy", -kOptionOffset, kOptionOffset, &set_[1]},
        {"ball_dz", -kOptionOffset, kOptionOffset, &set_[2]},
        {"ball_speed", 0, kOptionSpeed, &set_[kSpeedSlot]},
        {"ball_radius", kOptionRadius[0], kOptionRadius[1], &set_[kRadiusSlot]},
        {"ball_mass", kOptionMass[0], kOptionMass[1], &set_[kMassSlot]}};
    set_task_options("MIMoCatch-v0", known, options);
  }

  // Records whether the ball touches the right arm this step, and aims head and eyes at it.
  void after_physics(MimoCore& core) override {
    const mjModel* m = model_;
    mjData* d = core.data();
    bool contact = false;
    for (int i = 0; i < d->ncon && !contact; ++i) {
      const mjContact& c = d->contact[i];
      const int other = c.geom1 == ball_geom_ ? c.geom2 : c.geom2 == ball_geom_ ? c.geom1 : -1;
      if (other < 0 || !sensing_[m->geom_bodyid[other]]) continue;
      mjtNum force[6];
      mj_contactForce(m, d, i, force);
      contact = std::abs(force[0]) >= kMinForce;
    }
    held_[held_at_++ % kHoldSteps] = contact;
    in_contact_ = contact;
    const double* ball = d->xpos + 3 * ball_body_;
    const double aim[3] = {ball[0] + aim_error_[0], ball[1] + aim_error_[1],
                           ball[2] + aim_error_[2]};
    tracking_.aim(m, d, aim);
  }

  void observe(const MimoCore&, std::span<double> extra, std::span<double>) override {
    extra[0] = radius_;
  }

  double after_step(const MimoCore& core, Info& info) override {
    const mjData* d = core.data();
    const double* ball = d->xpos + 3 * ball_body_;
    const double* hand = d->xpos + 3 * hand_;
    double v[3];
    mju_sub3(v, ball, hand);
    const bool success = std::ranges::all_of(held_, [](char h) { return h; });
    const bool failure = ball[2] < hand[2] - kDropHeight || mju_norm3(v) > kDropDistance;
    set_outcome(info, success, failure);
    double reward = in_contact_ ? kContactReward : 0;
    if (options_.action_penalty) reward -= kCostWeight * core.sim().actuation().cost();
    if (failure) reward -= kEndReward;
    if (success) reward += kEndReward;
    return reward;
  }

 private:
  // Reset options: offsets 0-2, then speed, radius, mass.
  static constexpr int kSpeedSlot = 3, kRadiusSlot = 4, kMassSlot = 5;
  std::array<std::optional<double>, 6> set_;
  SampleOptions options_;
  mjModel* model_;  // the core's own copy
  HeadTracking tracking_;
  int hand_, ball_body_, ball_geom_, ball_qpos_, ball_dof_, wrist_qpos_;
  std::vector<char> sensing_;
  std::vector<double> zero_, gains_, jittered_, low_, high_;
  int gain_steps_ = 0;
  std::array<char, kHoldSteps> held_{};
  int held_at_ = 0;
  bool in_contact_ = false;
  double radius_ = kRadius[1];
  std::array<double, 3> aim_error_{};
};

}  // namespace

SampleDefinition catch_definition() {
  SampleDefinition def{.name = "MIMoCatch-v0",
                       .max_episode_steps = 800,
                       .actuation = ActuationModel::kMuscle,
                       .touch = kSkin,
                       .extra_observation = 1};
  def.parameters = {{"ball_dx", -kOptionOffset, kOptionOffset},
                    {"ball_dy", -kOptionOffset, kOptionOffset},
                    {"ball_dz", -kOptionOffset, kOptionOffset},
                    {"ball_speed", 0, kOptionSpeed},
                    {"ball_radius", kOptionRadius[0], kOptionRadius[1]},
                    {"ball_mass", kOptionMass[0], kOptionMass[1]}};
  // The reference's view: tracking the root, looking at the hand from the side.
  def.camera_lookat = {0.15, -0.04, 0.6};
  def.camera_distance = 0.5;
  def.camera_azimuth = 120;
  def.camera_elevation = -30;
  def.scene = [](const SampleOptions& options) {
    scene::Composition c;
    c.version = model::MimoVersion::kV2;
    c.worlds = {sample_floor()};
    c.placement = {{0, 0, 0.35}, {1, 0, 0, 0}};
    // Right wrist and the four long fingers: 20 actuators; thumb and arm pinned.
    std::set<std::string> actuators = {
        "right_wrist_rotation", "right_wrist_flexion", "right_wrist_ulnar", "right_lf_side",
        "right_lf_meta",        "right_lf_knuckle",    "right_lf_middle",   "right_lf_distal"};
    for (const char* f : {"ff", "mf", "rf"}) {
      for (const char* j : {"side", "knuckle", "middle", "distal"}) {
        actuators.insert(std::string("right_") + f + "_" + j);
      }
    }
    c.emit.actuators = actuators;
    // Torque sensors of the right arm and hand only.
    std::set<std::string> sensors;
    for (const model::TorqueSensor& t : model::make_mimo_v2().torque_sensors) {
      const std::string& n = t.name;
      const bool other = n.find("eye") != std::string::npos || n.find("hip") != std::string::npos ||
                         n.find("knee") != std::string::npos ||
                         n.find("ankle") != std::string::npos || n.find("toe") != std::string::npos;
      if (n.starts_with("right_") && !other) sensors.insert(n);
    }
    c.emit.torque_sensors = sensors;
    for (const auto& [joint, angle] : kPinned) c.emit.lock_angles[joint] = angle;
    if (options.palm_up) c.emit.lock_angles[kWristRotation] = kPalmUpAngle;
    scene::WorldFragments task;
    task.worldbody =
        "<body name=\"target\" pos=\"0.24 -0.04 0.8\">\n<joint name=\"target_joint\" "
        "type=\"free\"/>\n<geom name=\"target\" type=\"sphere\" size=\"0.025\" mass=\"0.5\" "
        "rgba=\".9 .2 .2 1\" condim=\"6\" solimp=\"0.95 0.99 0.001 0.5 1\" "
        "solref=\"0.005 1\"/>\n</body>\n";
    task.equality =
        "<weld body1=\"upper_body\"/>\n<weld body1=\"lower_body\"/>\n<weld body1=\"left_hand\"/>\n"
        "<weld body1=\"left_foot\"/>\n<weld body1=\"right_foot\"/>\n";
    // Soft springs keep neighbouring fingers side by side.
    for (auto [a, b] : {std::pair{"ff", "mf"}, std::pair{"mf", "rf"}, std::pair{"rf", "lf"}}) {
      task.tendon += std::string("<fixed name=\"") + a + "_" + b +
                     "_side\" springlength=\"0\" stiffness=\".03\" limited=\"false\">\n"
                     "<joint joint=\"robot:right_" +
                     a +
                     "_side\" coef=\"1\"/>\n"
                     "<joint joint=\"robot:right_" +
                     b + "_side\" coef=\"-1\"/>\n</fixed>\n";
    }
    c.worlds.push_back(std::move(task));
    return c;
  };
  def.initial_state = [](const mjModel* m, mjData* d) {
    // The pinned joints start at their pins.
    for (const auto& [joint, angle] : kPinned) {
      d->qpos[qpos_address(m, std::string("robot:") + joint)] = angle;
    }
  };
  def.make = [](MimoCore& core, const SampleOptions& options) -> std::unique_ptr<Task> {
    return std::make_unique<Catch>(core, options);
  };
  return def;
}

}  // namespace cradle::envs

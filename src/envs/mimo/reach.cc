// MIMoReach-v0 (mimo_core.md §6.1): MIMo, welded in place without gravity, reaches with his right
// arm for a hovering ball; head and eyes follow the ball. Reward: minus the hand-ball distance,
// +100 when the ball is knocked more than 1 cm out of place (success, ends the episode).
#include <cmath>

#include "envs/mimo/sample_env.h"

namespace cradle::envs {
namespace {

constexpr double kTarget[3] = {0.3, -0.05, 0.7};  // the ball's XML position
constexpr double kKnockedOut = 0.01;              // m the ball must move for success
constexpr double kTouchReward = 100;
constexpr int kRandomResetSteps = 10;

class ReachEnv final : public MimoEnv {
 public:
  ReachEnv(std::shared_ptr<const SampleAssets> assets, std::uint64_t seed)
      : MimoEnv(std::move(assets), seed),
        tracking_(model()),
        target_body_(body_id(model(), "target")),
        target_qpos_(qpos_address(model(), "target_joint")),
        fingers_(body_id(model(), "right_fingers")),
        random_action_(action_space().size()) {}

 private:
  const double* target_pos() const { return data()->xpos + 3 * target_body_; }

  void reset_model() override {
    // A few random arm movements, then the ball moved within reach; everything at rest.
    const Box& space = action_space();
    for (int i = 0; i < kRandomResetSteps; ++i) {
      for (size_t k = 0; k < random_action_.size(); ++k) {
        random_action_[k] = rng().uniform(space.low[k], space.high[k]);
      }
      sim().actuation().apply(random_action_, d());
      sim().actuation().substep(d());
      raw_step();
      step_callback();
    }
    double* ball = d()->qpos + target_qpos_;
    ball[0] = kTarget[0] + rng().uniform(-0.1, 0);
    ball[1] = kTarget[1] + rng().uniform(-0.2, 0.1);
    ball[2] = kTarget[2] + rng().uniform(-0.1, 0);
    mju_zero(d()->qvel, model()->nv);
    mj_forward(model(), d());
    mju_copy3(start_, target_pos());
  }

  void step_callback() override { tracking_.aim(model(), d(), target_pos()); }

  bool is_success() override {
    double moved[3];
    mju_sub3(moved, target_pos(), start_);
    return mju_norm3(moved) > kKnockedOut;
  }

  double compute_reward() override {
    double v[3];
    mju_sub3(v, data()->xpos + 3 * fingers_, target_pos());
    return -mju_norm3(v) + (success() ? kTouchReward : 0);
  }

  HeadTracking tracking_;
  int target_body_, target_qpos_, fingers_;
  std::vector<double> random_action_;
  double start_[3] = {0, 0, 0};
};

}  // namespace

SampleDefinition reach_definition() {
  SampleDefinition def{.name = "MIMoReach-v0", .max_episode_steps = 1000};
  def.camera_lookat = {0.15, -0.1, 0.6};
  def.camera_distance = 1.0;
  def.camera_azimuth = 135;
  def.scene = [](const SampleOptions&) {
    scene::Composition c;
    c.worlds = {sample_floor()};
    c.placement = {{0, 0, 0.35}, {1, 0, 0, 0}};
    c.gravity = {0, 0, 0};
    // Right arm only: shoulder (3), elbow, wrist (3) and fingers.
    c.emit.actuators =
        std::set<std::string>{"right_shoulder_horizontal", "right_shoulder_abduction",
                              "right_shoulder_internal",   "right_elbow",
                              "right_wrist_rotation",      "right_wrist_flexion",
                              "right_wrist_ulnar",         "right_fingers"};
    scene::WorldFragments task;
    // The hovering ball: default density (65 g), bouncy direct stiffness/damping.
    task.worldbody =
        "<body name=\"target\" pos=\"0.3 -0.05 0.7\">\n<joint name=\"target_joint\" "
        "type=\"free\"/>\n<geom name=\"target\" type=\"sphere\" size=\"0.025\" rgba=\".9 .2 .2 1\" "
        "condim=\"6\" solimp=\"0.99 0.995 0.001 0.5 2\" solref=\"-20000 -20\"/>\n</body>\n";
    // The trunk, left hand and feet are welded in place; the mitten is welded to the palm.
    task.equality =
        "<weld body1=\"upper_body\"/>\n<weld body1=\"lower_body\"/>\n<weld body1=\"left_hand\"/>\n"
        "<weld body1=\"left_foot\"/>\n<weld body1=\"right_foot\"/>\n"
        "<weld body1=\"right_fingers\" body2=\"right_hand\"/>\n";
    c.worlds.push_back(std::move(task));
    return c;
  };
  def.make = [](std::shared_ptr<const SampleAssets> assets, std::uint64_t seed) {
    return std::unique_ptr<MimoEnv>(std::make_unique<ReachEnv>(std::move(assets), seed));
  };
  return def;
}

}  // namespace cradle::envs

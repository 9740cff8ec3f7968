// MIMoReach-v0 (mimo_core.md §6.1): MIMo, welded in place without gravity, reaches with his right
// arm for a hovering ball; head and eyes follow the ball. Reward: minus the hand-ball distance,
// +100 when the ball is knocked more than 1 cm out of place (success, ends the episode). Reset
// options target_dx, target_dy, target_dz fix the ball's offset from its XML position (a
// curriculum's reach distance) instead of the reference's uniform draw.
#include <array>
#include <cmath>
#include <optional>

#include "envs/mimo/sample_env.h"

namespace cradle::envs {
namespace {

constexpr double kTarget[3] = {0.3, -0.05, 0.7};  // the ball's XML position
constexpr double kKnockedOut = 0.01;              // m the ball must move for success
constexpr double kTouchReward = 100;
constexpr int kRandomResetSteps = 10;
// The reference's offset draw per axis (m), and the range a reset option may set.
constexpr double kOffset[3][2] = {{-0.1, 0}, {-0.2, 0.1}, {-0.1, 0}};
constexpr double kOptionRange = 0.3;

class Reach final : public SampleTask {
 public:
  explicit Reach(MimoCore& core)
      : tracking_(core.model()),
        target_body_(body_id(core.model(), "target")),
        target_qpos_(qpos_address(core.model(), "target_joint")),
        fingers_(body_id(core.model(), "right_fingers")),
        random_action_(core.action_space().size()) {}

  void initialize_episode(MimoCore& core, Rng& rng, std::span<double>) override {
    // A few random arm movements, then the ball moved within reach; everything at rest.
    const Box& space = core.action_space();
    const mjModel* m = core.model();
    mjData* d = core.data();
    for (int i = 0; i < kRandomResetSteps; ++i) {
      space.sample(rng, random_action_);
      core.sim().actuation().apply(random_action_, d);
      core.sim().actuation().substep(d);
      core.raw_step();
      after_physics(core);
    }
    // Every offset is drawn (the stream stays the same), then a set option replaces it.
    double* ball = d->qpos + target_qpos_;
    for (int i = 0; i < 3; ++i) {
      const double drawn = rng.uniform(kOffset[i][0], kOffset[i][1]);
      ball[i] = kTarget[i] + offset_[i].value_or(drawn);
    }
    mju_zero(d->qvel, m->nv);
    mj_forward(m, d);
    mju_copy3(start_, target_pos(d));
  }

  void after_physics(MimoCore& core) override {
    tracking_.aim(core.model(), core.data(), target_pos(core.data()));
  }

  void set_reset_options(const ResetOptions& options) override {
    const TaskOption known[] = {{"target_dx", -kOptionRange, kOptionRange, &offset_[0]},
                                {"target_dy", -kOptionRange, kOptionRange, &offset_[1]},
                                {"target_dz", -kOptionRange, kOptionRange, &offset_[2]}};
    set_task_options("MIMoReach-v0", known, options);
  }

  double after_step(const MimoCore& core, Info& info) override {
    const mjData* d = core.data();
    double moved[3], v[3];
    mju_sub3(moved, target_pos(d), start_);
    const bool success = mju_norm3(moved) > kKnockedOut;
    set_outcome(info, success, false);
    mju_sub3(v, d->xpos + 3 * fingers_, target_pos(d));
    return -mju_norm3(v) + (success ? kTouchReward : 0);
  }

 private:
  const double* target_pos(const mjData* d) const { return d->xpos + 3 * target_body_; }

  HeadTracking tracking_;
  int target_body_, target_qpos_, fingers_;
  std::vector<double> random_action_;
  double start_[3] = {0, 0, 0};
  std::array<std::optional<double>, 3> offset_;  // reset options (m)
};

}  // namespace

SampleDefinition reach_definition() {
  SampleDefinition def{.name = "MIMoReach-v0", .max_episode_steps = 1000};
  for (const char* name : {"target_dx", "target_dy", "target_dz"})
    def.parameters.push_back({name, -kOptionRange, kOptionRange});
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
  def.make = [](MimoCore& core, const SampleOptions&) -> std::unique_ptr<Task> {
    return std::make_unique<Reach>(core);
  };
  return def;
}

}  // namespace cradle::envs

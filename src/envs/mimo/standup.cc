// MIMoStandup-v0 (mimo_core.md §6.2): MIMo sits in a crib, feet welded to the floor and hands to
// the rail, head fixed, and learns to stand up. Reward: head height - 0.2 - 0.01 x squared
// controls; fixed 500-step episodes (success, head at 0.5 m, is reported but ends nothing).
#include <utility>

#include "core/xml.h"
#include "envs/mimo/sample_env.h"

namespace cradle::envs {
namespace {

constexpr double kGoalHeight = 0.5;    // m, head body origin
constexpr double kHeightOffset = 0.2;  // subtracted from the head height
constexpr double kControlCost = 0.01;
constexpr double kJointNoise = 0.01;  // rad, uniform per joint at reset
constexpr int kSettleSteps = 100;     // raw physics steps (0.5 s) into a crouch

// SITTING_POSITION: the free joint (position, quaternion), then joint angles (rad); head and eyes
// stay at 0.
constexpr double kRoot[7] = {-0.103287,   0.00444494, 0.0672742, 0.965518,
                             -0.00942109, -0.207444,  0.157016};
constexpr std::pair<const char*, double> kSitting[] = {
    {"hip_lean1", -0.0134586},
    {"hip_rot1", -0.259285},
    {"hip_bend1", 0.407198},
    {"hip_lean2", -0.0565839},
    {"hip_rot2", -0.248653},
    {"hip_bend2", 0.38224},
    {"right_shoulder_horizontal", 1.59608},
    {"right_shoulder_ad_ab", 2.57899},
    {"right_shoulder_rotation", 0.259329},
    {"right_elbow", -0.188292},
    {"right_hand1", -0.429857},
    {"right_hand2", -0.99162},
    {"right_hand3", -0.0568468},
    {"right_fingers", -1.4206},
    {"left_shoulder_horizontal", 0.778157},
    {"left_shoulder_ad_ab", 2.9349},
    {"left_shoulder_rotation", 1.16941},
    {"left_elbow", -0.547872},
    {"left_hand1", -1.54373},
    {"left_hand2", -0.98379},
    {"left_hand3", 0.225526},
    {"left_fingers", -1.27117},
    {"right_hip1", -2.26831},
    {"right_hip2", -0.295142},
    {"right_hip3", -0.313409},
    {"right_knee", -2.53125},
    {"right_foot1", -0.109924},
    {"right_foot2", -0.0352949},
    {"right_foot3", 0.106372},
    {"right_toes", 0.0205777},
    {"left_hip1", -2.118},
    {"left_hip2", -0.233242},
    {"left_hip3", 0.369615},
    {"left_knee", -2.34683},
    {"left_foot1", -0.279261},
    {"left_foot2", -0.477783},
    {"left_foot3", 0.111583},
    {"left_toes", 0.0182025},
};

class Standup final : public SampleTask {
 public:
  explicit Standup(MimoCore& core)
      : head_(body_id(core.model(), "head")), zero_(core.action_space().size(), 0.0) {}

  void initialize_episode(MimoCore& core, Rng& rng, std::span<double>) override {
    // Every hinge angle jittered, at rest, then the body sags into a crouch under zero action.
    const mjModel* m = core.model();
    mjData* d = core.data();
    for (int i = 7; i < m->nq; ++i) d->qpos[i] += rng.uniform(-kJointNoise, kJointNoise);
    mju_zero(d->qvel, m->nv);
    mj_forward(m, d);
    core.sim().actuation().apply(zero_, d);
    for (int i = 0; i < kSettleSteps; ++i) core.raw_step();
  }

  double after_step(const MimoCore& core, Info& info) override {
    const mjModel* m = core.model();
    const mjData* d = core.data();
    const double head_height = d->xpos[3 * head_ + 2];
    set_outcome(info, head_height >= kGoalHeight, false);
    double effort = 0;
    for (int u = 0; u < m->nu; ++u) effort += d->ctrl[u] * d->ctrl[u];
    return head_height - kHeightOffset - kControlCost * effort;
  }

 private:
  int head_;
  std::vector<double> zero_;
};

// The crib's rail in front of MIMo: a horizontal bar with ball ends and five bars below it.
std::string crib() {
  std::string xml =
      "<body name=\"crib\" pos=\"0.078 0 0.42\">\n"
      "<geom type=\"cylinder\" size=\"0.02 0.4\" euler=\"90 0 0\" rgba=\".9 .8 .6 1\"/>\n";
  for (double y : {-0.4, 0.4}) {
    xml +=
        "<geom type=\"sphere\" size=\"0.022\" pos=\"0 " + num(y) + " 0\" rgba=\".9 .8 .6 1\"/>\n";
  }
  for (double y : {-0.4, -0.2, 0.0, 0.2, 0.4}) {
    xml += "<geom type=\"cylinder\" size=\"0.01 0.2\" pos=\"0 " + num(y) +
           " -0.2\" rgba=\".9 .8 .6 1\"/>\n";
  }
  return xml + "</body>\n";
}

}  // namespace

SampleDefinition standup_definition() {
  SampleDefinition def{
      .name = "MIMoStandup-v0", .max_episode_steps = 500, .done_active = false, .vestibular = true};
  def.camera_lookat = {0, 0, 0.3};
  def.camera_distance = 1.4;
  def.camera_azimuth = 150;
  def.scene = [](const SampleOptions&) {
    scene::Composition c;
    c.worlds = {sample_floor()};
    c.placement = {{0, 0, 0.33}, {1, 0, 0, 0}};
    // Trunk, arms, hands, fingers and legs: 27 actuators; head and eyes locked straight.
    c.emit.act_groups = GroupFlags::all(false);
    for (Group g : {Group::kBody, Group::kArms, Group::kHands, Group::kFingers, Group::kLegs}) {
      c.emit.act_groups[g] = true;
    }
    c.emit.lock_groups[Group::kHead] = true;
    c.emit.lock_groups[Group::kEyes] = true;
    scene::WorldFragments task;
    task.worldbody = crib();
    // Feet on the floor, mittens on the rail (poses relative to the world, as the reference).
    task.equality =
        "<weld body1=\"left_foot\" relpose=\"0 -0.05 0 0.01 0 0 0\"/>\n"
        "<weld body1=\"right_foot\" relpose=\"0 0.05 0 0.01 0 0 0\"/>\n"
        "<weld body1=\"left_fingers\" relpose=\"0.1 0.1 0.45 0 -0.1 0.1 0\"/>\n"
        "<weld body1=\"right_fingers\" relpose=\"0.1 -0.1 0.45 0 0.1 0.1 0\"/>\n";
    c.worlds.push_back(std::move(task));
    return c;
  };
  def.initial_state = [](const mjModel* m, mjData* d) {
    const int root = qpos_address(m, "mimo_location");
    for (int i = 0; i < 7; ++i) d->qpos[root + i] = kRoot[i];
    for (const auto& [joint, angle] : kSitting) {
      d->qpos[qpos_address(m, std::string("robot:") + joint)] = angle;
    }
  };
  def.make = [](MimoCore& core, const SampleOptions&) -> std::unique_ptr<Task> {
    return std::make_unique<Standup>(core);
  };
  return def;
}

}  // namespace cradle::envs

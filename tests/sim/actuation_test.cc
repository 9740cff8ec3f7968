// Actuation models on a tiny two-joint arm (torque paths, clipping, muscle curves and activation
// dynamics, servo tracking) and on the composed self-touch scene (sizes, 200 random steps).
#include "sim/actuation.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "core/config.h"
#include "scene/compose.h"
#include "sim/muscle.h"

namespace cradle::sim {
namespace {

namespace fs = std::filesystem;
using scene::ModelPtr;

struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
using DataPtr = std::unique_ptr<mjData, DataDeleter>;

// Two links hanging off the world, hinged about y: robot:shoulder (range −1..1, springref 0.2)
// and robot:elbow (range −0.5..1.5, springref 0). Joint attributes and actuators vary per model;
// a stray non-act actuator checks that only act:* ones are driven.
ModelPtr arm(const std::string& joint_attrs, const std::string& actuators, bool gravity = false,
             const std::string& extra = "") {
  const std::string xml = R"(<mujoco>
  <compiler angle="radian"/>
  <option timestep="0.005" gravity="0 0 )" +
                          std::string(gravity ? "-9.81" : "0") +
                          R"("/>
  <size nuser_actuator="3"/>
  <worldbody>
    <body name="upper" pos="0 0 1">
      <joint name="robot:shoulder" axis="0 1 0" limited="true" range="-1 1" springref="0.2" )" +
                          joint_attrs + R"(/>
      <geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.02"/>
      <body name="lower" pos="0.2 0 0">
        <joint name="robot:elbow" axis="0 1 0" limited="true" range="-0.5 1.5" springref="0" )" +
                          joint_attrs + R"(/>
        <geom type="capsule" fromto="0 0 0 0.2 0 0" size="0.02"/>
      </body>
    </body>
  </worldbody>
  <actuator>)" + actuators +
                          R"(
    <motor name="stray" joint="robot:shoulder" gear="1"/>
  </actuator>)" + extra + R"(
</mujoco>)";
  return scene::compile_scene(scene::SceneFiles{.xml = xml});
}

constexpr const char* kSpringJoints = R"(stiffness="0.5" damping="0.2" armature="0.01")";
constexpr const char* kMotors = R"(
    <motor name="act:shoulder" joint="robot:shoulder" gear="2" ctrllimited="true" ctrlrange="-1 1"
           forcelimited="true" forcerange="-1 0.5" user="1.5 10 8"/>
    <motor name="act:elbow" joint="robot:elbow" gear="0.5" ctrllimited="true" ctrlrange="-1 1"
           forcelimited="true" forcerange="-0.6 1" user="2 3 4"/>)";

constexpr const char* kMuscleJoints = R"(stiffness="0" damping="0.01" armature="0.01")";
constexpr const char* kMuscleMotors = R"(
    <motor name="act:shoulder" joint="robot:shoulder" gear="2" ctrllimited="false"
           forcelimited="false" user="1.5 10 8"/>
    <motor name="act:elbow" joint="robot:elbow" gear="0.5" ctrllimited="false"
           forcelimited="false" user="2 3 4"/>)";

constexpr const char* kServoJoints = R"(stiffness="0" damping="1" armature="0.01")";
constexpr double kServoGain = 20;
constexpr const char* kServos = R"(
    <position name="act:shoulder" joint="robot:shoulder" kp="20" ctrllimited="true"
              ctrlrange="-1 1"/>
    <position name="act:elbow" joint="robot:elbow" kp="20" ctrllimited="true"
              ctrlrange="-0.5 1.5"/>)";

DataPtr make_data(const mjModel* m) { return DataPtr(mj_makeData(m)); }

// One env step in the documented order: apply once, then substep → mj_step per physics step.
void env_step(const mjModel* m, mjData* d, Actuation& act, std::span<const double> action,
              int frame_skip = 1) {
  act.apply(action, d);
  for (int k = 0; k < frame_skip; ++k) {
    act.substep(d);
    mj_step(m, d);
  }
}

std::vector<double> observe(const Actuation& act, const mjData* d) {
  std::vector<double> out(act.observation_size());
  act.observe(d, out);
  return out;
}

// ---------------------------------------------------------------------------------------------
// Spring-damper

TEST(SpringDamper, BoundsAreTheForceRange) {
  const ModelPtr m = arm(kSpringJoints, kMotors);
  const auto act = make_actuation(ActuationModel::kSpringDamper, m.get());
  const Box& box = act->action_space();
  EXPECT_EQ(box.shape, std::vector<int>{2});
  EXPECT_EQ(box.dtype, DType::kFloat32);
  EXPECT_EQ(box.low, (std::vector<double>{-1, -0.6}));
  EXPECT_EQ(box.high, (std::vector<double>{0.5, 1}));
  EXPECT_EQ(act->observation_size(), 4);
}

TEST(SpringDamper, JointTorqueIsGearTimesClippedControl) {
  const ModelPtr m = arm(kSpringJoints, kMotors);
  const DataPtr d = make_data(m.get());
  const auto act = make_actuation(ActuationModel::kSpringDamper, m.get());
  const int stray = mj_name2id(m.get(), mjOBJ_ACTUATOR, "stray");

  // In range: passed through.
  const std::vector<double> inside = {0.3, -0.2};
  act->apply(inside, d.get());
  mj_forward(m.get(), d.get());
  EXPECT_DOUBLE_EQ(d->qfrc_actuator[0], 2 * 0.3);
  EXPECT_DOUBLE_EQ(d->qfrc_actuator[1], 0.5 * -0.2);
  EXPECT_EQ(d->ctrl[stray], 0);
  EXPECT_EQ(observe(*act, d.get()), (std::vector<double>{0.3, -0.2, 2 * 0.3, 0.5 * -0.2}));

  // Out of range: clipped to the asymmetric force range on each side.
  const std::vector<double> outside = {5, -5};
  act->apply(outside, d.get());
  mj_forward(m.get(), d.get());
  EXPECT_DOUBLE_EQ(d->qfrc_actuator[0], 2 * 0.5);
  EXPECT_DOUBLE_EQ(d->qfrc_actuator[1], 0.5 * -0.6);
  EXPECT_EQ(observe(*act, d.get()), (std::vector<double>{0.5, -0.6, 1.0, -0.3}));
  const std::vector<double> other_side = {-5, 5};
  act->apply(other_side, d.get());
  mj_forward(m.get(), d.get());
  EXPECT_DOUBLE_EQ(d->qfrc_actuator[0], 2 * -1.0);
  EXPECT_DOUBLE_EQ(d->qfrc_actuator[1], 0.5 * 1.0);

  act->reset(d.get());
  EXPECT_EQ(observe(*act, d.get()), (std::vector<double>(4, 0.0)));
  EXPECT_EQ(act->cost(), 0);
}

TEST(SpringDamper, CostWeighsSquaredControlsByGear) {
  const ModelPtr m = arm(kSpringJoints, kMotors);
  const DataPtr d = make_data(m.get());
  const auto act = make_actuation(ActuationModel::kSpringDamper, m.get());
  const std::vector<double> action = {0.5, -0.6};
  act->apply(action, d.get());
  // (0.25·2 + 0.36·0.5) / (2 · (2 + 0.5)) = 0.68 / 5.
  EXPECT_NEAR(act->cost(), 0.136, 1e-15);
}

TEST(SpringDamper, RejectsOtherActuators) {
  EXPECT_THROW(
      make_actuation(ActuationModel::kSpringDamper, arm(kMuscleJoints, kMuscleMotors).get()),
      std::runtime_error);
  EXPECT_THROW(make_actuation(ActuationModel::kSpringDamper, arm(kServoJoints, kServos).get()),
               std::runtime_error);
}

// ---------------------------------------------------------------------------------------------
// Muscle curves

TEST(MuscleCurves, Bump) {
  using muscle::bump;
  EXPECT_EQ(bump(0.5, 0.5, 1, 1.6), 0);
  EXPECT_EQ(bump(1.6, 0.5, 1, 1.6), 0);
  EXPECT_EQ(bump(1, 0.5, 1, 1.6), 1);
  EXPECT_DOUBLE_EQ(bump(0.75, 0.5, 1, 1.6), 0.5);  // rising inflection
  EXPECT_DOUBLE_EQ(bump(1.3, 0.5, 1, 1.6), 0.5);   // falling inflection
  // Quarter of the way up: ½ · (0.125 / 0.25)² = 0.125.
  EXPECT_DOUBLE_EQ(bump(0.625, 0.5, 1, 1.6), 0.125);
  // Between the falling inflection and the end: ½ · (1.45 − 1.6)² / 0.3² = 0.125.
  EXPECT_NEAR(bump(1.45, 0.5, 1, 1.6), 0.125, 1e-15);
}

TEST(MuscleCurves, ForceLength) {
  using muscle::bump;
  using muscle::force_length;
  EXPECT_DOUBLE_EQ(force_length(1), 1);  // the shoulder term vanishes above 0.95
  EXPECT_EQ(force_length(0.5), 0);
  EXPECT_EQ(force_length(1.6), 0);
  // At 0.725 the shoulder peaks (0.15) on top of the main bump.
  EXPECT_DOUBLE_EQ(force_length(0.725), bump(0.725, 0.5, 1, 1.6) + 0.15);
  EXPECT_DOUBLE_EQ(force_length(0.9), bump(0.9, 0.5, 1, 1.6) + 0.15 * bump(0.9, 0.5, 0.725, 0.95));
}

TEST(MuscleCurves, ForceVelocity) {
  using muscle::force_velocity;
  EXPECT_EQ(force_velocity(-2), 0);
  EXPECT_EQ(force_velocity(-1), 0);
  EXPECT_DOUBLE_EQ(force_velocity(-0.5), 0.25);
  EXPECT_EQ(force_velocity(0), 1);
  EXPECT_DOUBLE_EQ(force_velocity(0.1), 1.2 - 0.01 / 0.2);
  EXPECT_DOUBLE_EQ(force_velocity(0.2), 1.2);
  EXPECT_EQ(force_velocity(3), 1.2);
}

TEST(MuscleCurves, ForcePassive) {
  using muscle::force_passive;
  EXPECT_EQ(force_passive(0.8), 0);
  EXPECT_EQ(force_passive(1), 0);
  EXPECT_NEAR(force_passive(1.15), 0.25 * 1.3 * 0.125, 1e-15);
  EXPECT_DOUBLE_EQ(force_passive(1.3), 0.325);
  EXPECT_DOUBLE_EQ(force_passive(1.6), 0.25 * 1.3 * 4);  // linear beyond 1.3: 1 + 3·0.3/0.3
  EXPECT_DOUBLE_EQ(muscle::force(1.3, 0, 0.5), 0.5 * 0.5 + 0.325);
}

// ---------------------------------------------------------------------------------------------
// Muscle model

// Moment arms and reference lengths of the test arm's shoulder (range −1..1, springref 0.2):
// φ ∈ [−1.2, 0.8], m1 = 0.3/2, L1_ref = 0.75 + m1·1.2, m2 = −m1, L2_ref = 0.75 − m2·0.8.
constexpr double kArm = (0.3 + 1e-10) / (2 + 1e-10);
constexpr double kRef1 = 0.75 + kArm * 1.2;
constexpr double kRef2 = 0.75 + kArm * 0.8;

TEST(Muscle, SpacesAndSizes) {
  const ModelPtr m = arm(kMuscleJoints, kMuscleMotors);
  const auto act = make_actuation(ActuationModel::kMuscle, m.get());
  const Box& box = act->action_space();
  EXPECT_EQ(box.shape, std::vector<int>{4});
  EXPECT_EQ(box.dtype, DType::kFloat32);
  EXPECT_EQ(box.low, std::vector<double>(4, 0.0));
  EXPECT_EQ(box.high, std::vector<double>(4, 1.0));
  EXPECT_EQ(act->observation_size(), 8);
  EXPECT_DOUBLE_EQ(m->qpos_spring[0], 0.2);  // springref in radians
}

TEST(Muscle, ActivationFollowsTheTimeConstant) {
  const ModelPtr m = arm(kMuscleJoints, kMuscleMotors);
  const DataPtr d = make_data(m.get());
  const auto act = make_actuation(ActuationModel::kMuscle, m.get());
  act->reset(d.get());
  const std::vector<double> full(4, 1.0);
  // apply() sets the target only; each substep moves dt/τ = 0.005/0.01 = half-way.
  act->apply(full, d.get());
  EXPECT_EQ(observe(*act, d.get())[0], 0);
  for (int k = 1; k <= 6; ++k) {
    act->substep(d.get());
    const std::vector<double> obs = observe(*act, d.get());
    for (int j = 0; j < 4; ++j) EXPECT_DOUBLE_EQ(obs[j], 1 - std::pow(0.5, k)) << k;
  }
  // Targets are clipped to [0, 1]: −3 acts as 0, so the next substep halves the activation.
  const std::vector<double> below(4, -3.0);
  act->apply(below, d.get());
  act->substep(d.get());
  EXPECT_DOUBLE_EQ(observe(*act, d.get())[0], 0.5 * (1 - std::pow(0.5, 6)));

  // Cost with every activation at 0.5: Σ 0.25·FMAX / (2n ΣFMAX) = 0.25 / 4.
  act->reset(d.get());
  act->apply(full, d.get());
  act->substep(d.get());
  EXPECT_DOUBLE_EQ(act->cost(), 0.0625);
  act->reset(d.get());
  EXPECT_EQ(act->cost(), 0);
  EXPECT_EQ(observe(*act, d.get()), std::vector<double>(8, 0.0));
}

TEST(Muscle, TorqueAtSpringrefMatchesTheCurves) {
  const ModelPtr m = arm(kMuscleJoints, kMuscleMotors);
  const DataPtr d = make_data(m.get());
  const auto act = make_actuation(ActuationModel::kMuscle, m.get());
  d->qpos[0] = 0.2;  // shoulder at springref, at rest
  act->reset(d.get());

  // Drive both shoulder muscles (action entries 0 and 2) to full activation without moving.
  auto torque_with = [&](double neg, double pos) {
    act->reset(d.get());
    const std::vector<double> action = {neg, 0, pos, 0};
    act->apply(action, d.get());
    for (int k = 0; k < 80; ++k) act->substep(d.get());
    mj_forward(m.get(), d.get());
    return d->qfrc_actuator[0];
  };
  const double f1 = muscle::force_length(kRef1);
  const double f2 = muscle::force_length(kRef2);
  const double tau_neg = torque_with(1, 0);
  const double tau_pos = torque_with(0, 1);
  const double tau_both = torque_with(1, 1);
  EXPECT_NEAR(tau_neg, -kArm * f1 * 10, 1e-12);
  EXPECT_NEAR(tau_pos, kArm * f2 * 8, 1e-12);
  // Antagonists partly cancel: the sum lies strictly between the two alone.
  EXPECT_LT(tau_neg, 0);
  EXPECT_GT(tau_pos, 0);
  EXPECT_NEAR(tau_both, tau_neg + tau_pos, 1e-12);
  EXPECT_GT(tau_both, tau_neg);
  EXPECT_LT(tau_both, tau_pos);
  // Observed forces are F·FMAX, activations are 1.
  const std::vector<double> obs = observe(*act, d.get());
  EXPECT_DOUBLE_EQ(obs[0], 1);
  EXPECT_DOUBLE_EQ(obs[2], 1);
  EXPECT_NEAR(obs[4], f1 * 10, 1e-12);
  EXPECT_NEAR(obs[6], f2 * 8, 1e-12);
  // The elbow's relaxed muscles at springref (lengths < 1) produce nothing.
  EXPECT_EQ(obs[5], 0);
  EXPECT_EQ(obs[7], 0);
  EXPECT_EQ(d->qfrc_actuator[1], 0);
}

TEST(Muscle, TorqueStaysWithinTheMuscleLimits) {
  const ModelPtr m = arm(kMuscleJoints, kMuscleMotors, /*gravity=*/true);
  const DataPtr d = make_data(m.get());
  const auto act = make_actuation(ActuationModel::kMuscle, m.get());
  act->reset(d.get());
  // Largest normalised force while the fibres stay near [0.75, 1.05]: FL ≤ 1.15, FV ≤ 1.2, plus
  // passive force far beyond that range.
  const double fcap = 1.15 * 1.2 + muscle::force_passive(1.3);
  const double gear[2] = {2, 0.5};
  const double arm_elbow = (0.3 + 1e-10) / (2 + 1e-10);  // the elbow's range is also 2 rad wide
  const double bound[2] = {kArm * (10 + 8) * fcap, arm_elbow * (3 + 4) * fcap};
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.2, 1.2);
  std::vector<double> action(4);
  for (int step = 0; step < 1000; ++step) {
    if (step % 50 == 0) {
      for (double& a : action) a = u(rng);
    }
    env_step(m.get(), d.get(), *act, action, 2);
    for (int i = 0; i < 2; ++i) {
      ASSERT_TRUE(std::isfinite(d->ctrl[i]));
      EXPECT_LE(std::abs(gear[i] * d->ctrl[i]), bound[i]) << step;
    }
  }
}

TEST(Muscle, PositiveMusclesBendTheJointUp) {
  const ModelPtr m = arm(kMuscleJoints, kMuscleMotors);
  const DataPtr d = make_data(m.get());
  const auto act = make_actuation(ActuationModel::kMuscle, m.get());
  act->reset(d.get());
  const std::vector<double> action = {0, 0, 1, 1};
  for (int step = 0; step < 100; ++step) env_step(m.get(), d.get(), *act, action);
  EXPECT_GT(d->qpos[0], 0.5);
  EXPECT_GT(d->qpos[1], 0.5);
}

TEST(Muscle, RejectsOtherActuators) {
  // Limited motors on springy joints are the spring-damper scene.
  EXPECT_THROW(make_actuation(ActuationModel::kMuscle, arm(kSpringJoints, kMotors).get()),
               std::runtime_error);
  EXPECT_THROW(make_actuation(ActuationModel::kMuscle, arm(kSpringJoints, kMuscleMotors).get()),
               std::runtime_error);
  EXPECT_THROW(make_actuation(ActuationModel::kMuscle, arm(kServoJoints, kServos).get()),
               std::runtime_error);
}

// ---------------------------------------------------------------------------------------------
// Positional model

TEST(Positional, BoundsAreJointRangesAndTargetsAreClipped) {
  const ModelPtr m = arm(kServoJoints, kServos);
  const DataPtr d = make_data(m.get());
  const auto act = make_actuation(ActuationModel::kPositional, m.get());
  const Box& box = act->action_space();
  EXPECT_EQ(box.shape, std::vector<int>{2});
  EXPECT_EQ(box.dtype, DType::kFloat32);
  EXPECT_EQ(box.low, (std::vector<double>{-1, -0.5}));
  EXPECT_EQ(box.high, (std::vector<double>{1, 1.5}));
  EXPECT_EQ(act->observation_size(), 2);
  const std::vector<double> wild = {3, -3};
  act->apply(wild, d.get());
  EXPECT_EQ(observe(*act, d.get()), (std::vector<double>{1, -0.5}));
  EXPECT_EQ(act->cost(), 0);
  act->reset(d.get());
  EXPECT_EQ(observe(*act, d.get()), (std::vector<double>{0, 0}));
}

TEST(Positional, ServoReachesAndHoldsTarget) {
  const ModelPtr m = arm(kServoJoints, kServos);
  const DataPtr d = make_data(m.get());
  const auto act = make_actuation(ActuationModel::kPositional, m.get());
  act->reset(d.get());
  const std::vector<double> target = {0.5, -0.3};
  for (int step = 0; step < 400; ++step) env_step(m.get(), d.get(), *act, target);  // 2 s
  EXPECT_NEAR(d->qpos[0], 0.5, 1e-3);
  EXPECT_NEAR(d->qpos[1], -0.3, 1e-3);
  EXPECT_NEAR(d->qvel[0], 0, 1e-3);
}

TEST(Positional, GravitySagMatchesServoStiffness) {
  const ModelPtr m = arm(kServoJoints, kServos, /*gravity=*/true);
  const DataPtr d = make_data(m.get());
  const auto act = make_actuation(ActuationModel::kPositional, m.get());
  act->reset(d.get());
  const std::vector<double> target = {0, 0};  // both links horizontal
  for (int step = 0; step < 800; ++step) env_step(m.get(), d.get(), *act, target);  // 4 s
  mj_forward(m.get(), d.get());
  // At rest the servo balances gravity: kp · (target − q) = gravity torque.
  for (int i = 0; i < 2; ++i) {
    const double error = target[i] - d->qpos[i];
    EXPECT_NEAR(kServoGain * error, d->qfrc_bias[i], 1e-3) << i;
    std::printf("servo kp %g, steady-state error with gravity, joint %d: %.4f rad\n", kServoGain, i,
                -error);
  }
  EXPECT_GT(d->qpos[0], 0.01);  // the arm sags (positive rotation about y lowers +x)
}

TEST(Positional, LockedJointKeepsItsLockAngle) {
  const ModelPtr m = arm(kServoJoints, kServos, false,
                         R"(
  <equality><joint joint1="robot:elbow" active="true"/></equality>)");
  const DataPtr d = make_data(m.get());
  const auto act = make_actuation(ActuationModel::kPositional, m.get());
  const std::vector<double> target = {0.5, 1.0};
  act->apply(target, d.get());
  EXPECT_EQ(observe(*act, d.get()), (std::vector<double>{0.5, 0}));
}

TEST(Positional, RejectsOtherActuators) {
  EXPECT_THROW(make_actuation(ActuationModel::kPositional, arm(kSpringJoints, kMotors).get()),
               std::runtime_error);
  EXPECT_THROW(make_actuation(ActuationModel::kPositional, arm(kMuscleJoints, kMuscleMotors).get()),
               std::runtime_error);
}

// ---------------------------------------------------------------------------------------------
// Composed self-touch scene

struct SceneCase {
  ActuationModel kind;
  int action_dim;
  int observation_size;
};

TEST(ActuationScene, SelfTouchSizesAndRandomSteps) {
  const Config base = load_config(fs::path(CRADLE_SOURCE_DIR) / "configs" / "config_selftouch.yml");
  const SceneCase cases[] = {{ActuationModel::kSpringDamper, 30, 60},
                             {ActuationModel::kMuscle, 60, 120},
                             {ActuationModel::kPositional, 30, 30}};
  std::vector<ModelPtr> models;
  for (const SceneCase& c : cases) {
    Config config = base;
    config.actuation_model = c.kind;
    models.push_back(scene::compile_scene(scene::compose_scene(config)));
    const mjModel* m = models.back().get();
    const auto act = make_actuation(c.kind, m);
    const Box& box = act->action_space();
    ASSERT_EQ(box.size(), c.action_dim) << actuation_model_name(c.kind);
    EXPECT_EQ(act->observation_size(), c.observation_size);

    // 200 steps of random actions reaching a little past the bounds.
    const DataPtr d = make_data(m);
    act->reset(d.get());
    std::mt19937 rng(11);
    std::vector<double> action(box.size());
    std::vector<double> obs(act->observation_size());
    for (int step = 0; step < 200; ++step) {
      for (int i = 0; i < box.size(); ++i) {
        const double pad = 0.1 * (box.high[i] - box.low[i]);
        action[i] =
            std::uniform_real_distribution<double>(box.low[i] - pad, box.high[i] + pad)(rng);
      }
      env_step(m, d.get(), *act, action, config.frame_skip);
      act->observe(d.get(), obs);
      for (double v : obs) ASSERT_TRUE(std::isfinite(v)) << step;
    }
    for (int w = 0; w < mjNWARNING; ++w) EXPECT_EQ(d->warning[w].number, 0) << "warning " << w;
    for (int j = 0; j < m->nq; ++j) EXPECT_TRUE(std::isfinite(d->qpos[j]));
    for (int j = 0; j < m->nv; ++j) EXPECT_TRUE(std::isfinite(d->qvel[j]));
    EXPECT_TRUE(std::isfinite(act->cost()));
  }
  // Each scene fits only its own model.
  for (int s = 0; s < 3; ++s) {
    for (int k = 0; k < 3; ++k) {
      if (s == k) continue;
      EXPECT_THROW(make_actuation(cases[k].kind, models[s].get()), std::runtime_error) << s << k;
    }
  }
}

// The shipped FMAX values were calibrated so that a fully active muscle at the zero pose gives the
// motor's strength gear·|forcerange| (mimo_core.md §2.1, §3.2); checks the whole chain (user
// values, springref in radians, moment arms, curves, ctrl = τ / gear) on well-calibrated joints.
TEST(ActuationScene, MuscleIsometricTorqueMatchesMotorStrength) {
  Config config = load_config(fs::path(CRADLE_SOURCE_DIR) / "configs" / "config_selftouch.yml");
  config.actuation_model = ActuationModel::kMuscle;
  const ModelPtr m = scene::compile_scene(scene::compose_scene(config));
  const DataPtr d = make_data(m.get());
  const auto act = make_actuation(ActuationModel::kMuscle, m.get());
  const std::vector<int> ids = mimo_actuators(m.get());
  const int n = static_cast<int>(ids.size());
  struct Strength {
    const char* name;
    double neg, pos;  // N·m, from the spring-damper table
  };
  const Strength strengths[] = {{"act:hip_bend", 10.58, 8.094},
                                {"act:head_tilt", 3.3, 1.815},
                                {"act:right_wrist_flexion", 1.24, 0.7068},
                                {"act:left_hip_rotation", 2.655, 3.54}};
  for (int side = 0; side < 2; ++side) {
    act->reset(d.get());
    std::vector<double> action(2 * n, 0.0);
    std::fill_n(action.begin() + side * n, n, 1.0);
    act->apply(action, d.get());
    for (int k = 0; k < 80; ++k) act->substep(d.get());
    for (const Strength& s : strengths) {
      const int id = mj_name2id(m.get(), mjOBJ_ACTUATOR, s.name);
      const double torque = d->ctrl[id] * m->actuator_gear[6 * id];
      const double expected = side == 0 ? -s.neg : s.pos;
      EXPECT_NEAR(torque, expected, 0.01 * std::abs(expected)) << s.name << " side " << side;
    }
  }
}

}  // namespace
}  // namespace cradle::sim

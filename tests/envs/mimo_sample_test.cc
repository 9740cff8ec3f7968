// MIMo's sample envs: registry, spaces, seeded resets, and each task's reward, success and failure
// on scripted states.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "envs/mimo/sample_env.h"

namespace cradle::envs {
namespace {

// Compiled once per env name for the whole binary.
std::shared_ptr<const SampleAssets> assets(const std::string& name, SampleOptions options = {}) {
  static std::map<std::string, std::shared_ptr<const SampleAssets>> cache;
  options.vision_resolution = 16;
  options.render_size = 64;
  const std::string key =
      name + (options.actuation ? "/custom" : "") + (options.palm_up ? "/palm_up" : "");
  auto& slot = cache[key];
  if (!slot) slot = make_sample_assets(name, options);
  return slot;
}

// Every observation entry's bytes, concatenated.
std::vector<std::byte> snapshot(const MimoEnv& env) {
  std::vector<std::byte> out;
  for (int i = 0; i < env.observation().count(); ++i) {
    const auto bytes = env.observation().bytes(i);
    out.insert(out.end(), bytes.begin(), bytes.end());
  }
  return out;
}

double distance(const mjData* d, int a, int b) {
  double v[3];
  mju_sub3(v, d->xpos + 3 * a, d->xpos + 3 * b);
  return mju_norm3(v);
}

// A fixed mid-range action.
std::vector<double> mid_action(const MimoEnv& env) {
  const Box& space = env.action_space();
  std::vector<double> a(space.size());
  for (size_t k = 0; k < a.size(); ++k) a[k] = 0.3 * space.low[k] + 0.7 * space.high[k];
  return a;
}

TEST(MimoSample, RegistryNamesAndUnknownName) {
  const std::vector<std::string> expected = {"MIMoBench-v0", "MIMoBenchV2-v0", "MIMoShowroom-v0",
                                             "MIMoReach-v0", "MIMoStandup-v0", "MIMoSelfBody-v0",
                                             "MIMoCatch-v0"};
  EXPECT_EQ(sample_env_names(), expected);
  try {
    make_sample_assets("MIMoFly-v0");
    FAIL() << "no error for an unknown env";
  } catch (const UserError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("MIMoFly-v0"), std::string::npos);
    EXPECT_NE(message.find("MIMoCatch-v0"), std::string::npos);
    EXPECT_EQ(message.find('\n'), std::string::npos);
  }
  EXPECT_EQ(sample_env_id("selfbody"), "MIMoSelfBody-v0");
  EXPECT_THROW(sample_env_id("dance"), UserError);
}

// Actuators, action and observation sizes from mimo_core.md §1-4 and §6.
TEST(MimoSample, SpacesMatchTheReference) {
  struct Sizes {
    std::string name;
    int actuators, actions, proprio, touch, goal;
  };
  // Proprioception: actuation (2n spring-damper, 4n muscle) + limits, qpos, qvel per joint
  // + 3 per torque sensor (+1: catch's ball radius).
  const Sizes expected[] = {
      {"MIMoReach-v0", 8, 8, 2 * 8 + 3 * 47 + 63, 0, 0},
      {"MIMoStandup-v0", 27, 27, 2 * 27 + 3 * 47 + 63, 0, 0},
      {"MIMoSelfBody-v0", 8, 8, 2 * 8 + 3 * 47 + 63, -1, 11},
      {"MIMoCatch-v0", 20, 40, 4 * 20 + 3 * 91 + 3 * 19 + 1, -1, 0},
  };
  for (const Sizes& s : expected) {
    SCOPED_TRACE(s.name);
    const auto env = make_sample_env(assets(s.name));
    EXPECT_EQ(env->model()->nu, s.actuators);
    EXPECT_EQ(env->action_space().size(), s.actions);
    const DictSpace& space = env->observation_space();
    EXPECT_EQ(space.find("observation")->size(), s.proprio);
    EXPECT_EQ(space.find("observation")->dtype, DType::kFloat64);
    if (s.touch == 0) {
      EXPECT_EQ(space.find("touch"), nullptr);
    } else {
      ASSERT_NE(space.find("touch"), nullptr);
      EXPECT_EQ(space.find("touch")->dtype, DType::kFloat32);
      EXPECT_EQ(space.find("touch")->size(), 3 * env->touch()->sensor_count());
    }
    EXPECT_EQ(space.find("vestibular") != nullptr, s.name == "MIMoStandup-v0");
    if (s.goal > 0) {
      EXPECT_EQ(space.find("achieved_goal")->size(), s.goal);
      EXPECT_EQ(space.find("desired_goal")->size(), s.goal);
    } else {
      EXPECT_EQ(space.find("desired_goal"), nullptr);
    }
  }
  // Spring-damper catch: one action per actuator.
  SampleOptions sd;
  sd.actuation = ActuationModel::kSpringDamper;
  EXPECT_EQ(make_sample_env(assets("MIMoCatch-v0", sd))->action_space().size(), 20);
}

TEST(MimoSample, SeededResetsAreDeterministic) {
  for (const char* name : {"MIMoReach-v0", "MIMoStandup-v0", "MIMoSelfBody-v0", "MIMoCatch-v0"}) {
    SCOPED_TRACE(name);
    auto run = [&](MimoEnv& env, std::uint64_t seed) {
      env.reset(seed);
      std::vector<std::byte> all = snapshot(env);
      const std::vector<double> a = mid_action(env);
      for (int i = 0; i < 3; ++i) {
        env.step(a);
        const auto s = snapshot(env);
        all.insert(all.end(), s.begin(), s.end());
      }
      return all;
    };
    auto a = make_sample_env(assets(name), 1);
    auto b = make_sample_env(assets(name), 2);
    const auto first = run(*a, 7);
    EXPECT_EQ(first, run(*b, 7));  // another env, same seed
    EXPECT_EQ(first, run(*a, 7));  // the same env again
    // Another seed starts elsewhere (self-body: another target for some seed).
    bool differs = false;
    for (std::uint64_t seed = 8; seed < 12 && !differs; ++seed) differs = run(*b, seed) != first;
    EXPECT_TRUE(differs);
  }
}

TEST(MimoSample, ReachRewardsDistanceAndKnockingTheBallAway) {
  auto env = make_sample_env(assets("MIMoReach-v0"), 3);
  const mjModel* m = env->model();
  const int fingers = body_id(m, "right_fingers"), target = body_id(m, "target");
  const std::vector<double> zero(8, 0.0);
  StepResult r = env->step(zero);
  EXPECT_FALSE(env->success());
  EXPECT_FALSE(r.terminated);
  EXPECT_NEAR(r.reward, -distance(env->data(), fingers, target), 1e-12);
  EXPECT_LT(r.reward, -0.05);  // out of reach of a resting arm
  // The head turned towards the ball.
  EXPECT_NE(env->data()->qpos[qpos_address(m, "robot:head_swivel")], 0);

  // Knocked 2 cm out of place: success, +100, the episode ends.
  env->mutable_data()->qpos[qpos_address(m, "target_joint")] += 0.02;
  r = env->step(zero);
  EXPECT_TRUE(env->success());
  EXPECT_TRUE(r.terminated);
  EXPECT_NEAR(r.reward, 100 - distance(env->data(), fingers, target), 1e-12);
}

TEST(MimoSample, StandupRewardsHeadHeightMinusControlCost) {
  auto env = make_sample_env(assets("MIMoStandup-v0"), 3);
  const mjModel* m = env->model();
  const int head = body_id(m, "head");
  const std::vector<double> a = mid_action(*env);
  StepResult r = env->step(a);
  double effort = 0;
  for (int u = 0; u < m->nu; ++u) effort += env->data()->ctrl[u] * env->data()->ctrl[u];
  EXPECT_GT(effort, 0);
  const double head_z = env->data()->xpos[3 * head + 2];
  EXPECT_NEAR(r.reward, head_z - 0.2 - 0.01 * effort, 1e-12);
  EXPECT_LT(head_z, 0.5);  // crouching
  EXPECT_FALSE(env->success());

  // Standing straight: the head is above 0.5 m, success is reported but ends nothing.
  mjData* d = env->mutable_data();
  mju_zero(d->qpos, m->nq);
  d->qpos[2] = 0.35;
  d->qpos[3] = 1;
  mju_zero(d->qvel, m->nv);
  r = env->step(std::vector<double>(27, 0.0));
  EXPECT_GE(env->data()->xpos[3 * head + 2], 0.5);
  EXPECT_TRUE(env->success());
  EXPECT_FALSE(r.terminated);
  EXPECT_NEAR(r.reward, env->data()->xpos[3 * head + 2] - 0.2, 1e-12);
}

TEST(MimoSample, StandupTruncatesAt500Steps) {
  auto env = make_sample_env(assets("MIMoStandup-v0"), 4);
  const std::vector<double> zero(27, 0.0);
  for (int i = 1; i < 500; ++i) ASSERT_FALSE(env->step(zero).truncated) << i;
  EXPECT_TRUE(env->step(zero).truncated);
}

// Self-body: the first seed whose target is `body`.
std::uint64_t selfbody_seed(const std::string& body) {
  const std::vector<std::string> targets = selfbody_targets();
  const int want = static_cast<int>(std::ranges::find(targets, body) - targets.begin());
  auto env = make_sample_env(assets("MIMoSelfBody-v0"));
  for (std::uint64_t seed = 0; seed < 500; ++seed) {
    env->reset(seed);
    if (env->observation().f64(env->key_index("desired_goal"))[want] == 1) return seed;
  }
  return 1000;
}

// Self-body: poses the right arm so that the mitten presses on the left thigh.
bool press_mitten_on_left_thigh(MimoEnv& env) {
  const mjModel* m = env.model();
  mjData* d = env.mutable_data();
  const int fingers = body_id(m, "right_fingers"), thigh = body_id(m, "left_upper_leg");
  for (double h = -0.4; h <= 2.0; h += 0.2) {
    for (double e = -2.4; e <= 0; e += 0.2) {
      d->qpos[qpos_address(m, "robot:right_shoulder_horizontal")] = h;
      d->qpos[qpos_address(m, "robot:right_elbow")] = e;
      mj_forward(m, d);
      for (int i = 0; i < d->ncon; ++i) {
        const int b1 = m->geom_bodyid[d->contact[i].geom1];
        const int b2 = m->geom_bodyid[d->contact[i].geom2];
        if ((b1 == fingers && b2 == thigh) || (b2 == fingers && b1 == thigh)) return true;
      }
    }
  }
  return false;
}

TEST(MimoSample, SelfBodyRewardsTouchingTheTarget) {
  EXPECT_EQ(selfbody_targets().size(), 11u);
  const std::vector<double> zero(8, 0.0);
  // The target (left thigh) touched by the mitten: success, 500, and the achieved goal is the
  // desired one.
  auto env = make_sample_env(assets("MIMoSelfBody-v0"), selfbody_seed("left_upper_leg"));
  const auto desired = env->observation().f64(env->key_index("desired_goal"));
  EXPECT_EQ(std::ranges::count(desired, 1.0), 1);
  StepResult r = env->step(zero);
  EXPECT_FALSE(env->success());
  EXPECT_EQ(r.reward, -1);  // the hand touches nothing
  ASSERT_TRUE(press_mitten_on_left_thigh(*env));
  r = env->step(zero);
  EXPECT_TRUE(env->success());
  EXPECT_TRUE(r.terminated);
  EXPECT_EQ(r.reward, 500);
  const auto achieved = env->observation().f64(env->key_index("achieved_goal"));
  const auto goal = env->observation().f64(env->key_index("desired_goal"));
  const long target = std::ranges::find(goal, 1.0) - goal.begin();
  EXPECT_EQ(selfbody_targets()[target], "left_upper_leg");
  EXPECT_EQ(achieved[target], 1);

  // Another target (head): touching the thigh earns minus the mitten-head distance.
  env = make_sample_env(assets("MIMoSelfBody-v0"), selfbody_seed("head"));
  ASSERT_TRUE(press_mitten_on_left_thigh(*env));
  r = env->step(zero);
  EXPECT_FALSE(env->success());
  EXPECT_FALSE(r.terminated);
  const mjModel* m = env->model();
  EXPECT_NEAR(r.reward, -distance(env->data(), body_id(m, "right_fingers"), body_id(m, "head")),
              1e-12);
  EXPECT_LT(r.reward, -0.1);
}

TEST(MimoSample, CatchSucceedsAfterHoldingTheBallOneSecond) {
  auto env = make_sample_env(assets("MIMoCatch-v0"), 5);
  const mjModel* m = env->model();
  const int hand = body_id(m, "right_hand");
  const int ball = qpos_address(m, "target_joint");
  const int ball_dof = m->jnt_dofadr[mj_name2id(m, mjOBJ_JOINT, "target_joint")];
  const auto proprio = env->observation().f64(env->key_index("observation"));
  const double radius = proprio.back();
  EXPECT_GE(radius, 0.005);
  EXPECT_LE(radius, 0.025);
  EXPECT_EQ(m->geom_size[3 * mj_name2id(m, mjOBJ_GEOM, "target")], radius);

  // Before every step the ball is placed on the palm, moving into it at 0.3 m/s (a ball at rest
  // or pressed in deeper bounces off within the step's 10 ms).
  mjData* d = env->mutable_data();
  const std::vector<double> zero(env->action_space().size(), 0.0);
  auto place = [&] {
    mj_kinematics(m, d);  // the hand where it is now
    const double* x = d->xpos + 3 * hand;
    const double* r = d->xmat + 9 * hand;
    const double lift = 0.00584 + radius;  // palm half-thickness along the hand's y axis
    mju_zero(d->qvel + ball_dof, 6);
    for (int i = 0; i < 3; ++i) {
      d->qpos[ball + i] = x[i] + lift * r[3 * i + 1];
      d->qvel[ball_dof + i] = -0.3 * r[3 * i + 1];
    }
  };
  StepResult r;
  for (int i = 1; i < 100; ++i) {
    place();
    r = env->step(zero);
    ASSERT_FALSE(env->success()) << i;
    ASSERT_FALSE(env->failure()) << i;
    ASSERT_NEAR(r.reward, 1.0, 1e-9) << i;  // in contact, no effort
  }
  place();
  r = env->step(zero);
  EXPECT_TRUE(env->success());
  EXPECT_TRUE(r.terminated);
  EXPECT_NEAR(r.reward, 101.0, 1e-9);

  // A new episode forgets the contacts of the last one.
  env->reset(6);
  place();
  r = env->step(zero);
  EXPECT_FALSE(env->success());
}

TEST(MimoSample, CatchFailsWhenTheBallDrops) {
  auto env = make_sample_env(assets("MIMoCatch-v0"), 5);
  const mjModel* m = env->model();
  mjData* d = env->mutable_data();
  const int hand = body_id(m, "right_hand");
  const int ball = qpos_address(m, "target_joint");
  for (int i = 0; i < 3; ++i) d->qpos[ball + i] = d->xpos[3 * hand + i];
  d->qpos[ball + 2] -= 0.3;
  const StepResult r = env->step(std::vector<double>(env->action_space().size(), 0.0));
  EXPECT_TRUE(env->failure());
  EXPECT_TRUE(r.terminated);
  EXPECT_NEAR(r.reward, -100.0, 1e-9);
}

// The palm's normal is the hand's -y axis (the palm box is thin in y; fingers flex toward -y).
double palm_normal_z(const MimoEnv& env) {
  return -env.data()->xmat[9 * body_id(env.model(), "right_hand") + 7];
}

// The reference scene pins the arm but not the wrist: at rest the palm faces sideways (toward
// the body's midline). palm_up pins the wrist rotation at MIMo's first scene's -1.4 rad, which
// turns the palm up under the ball.
TEST(MimoSample, CatchPalmFacesSidewaysUnlessPinnedUp) {
  auto sideways = make_sample_env(assets("MIMoCatch-v0"), 1);
  EXPECT_LT(std::abs(palm_normal_z(*sideways)), 0.3);
  SampleOptions up;
  up.palm_up = true;
  auto upturned = make_sample_env(assets("MIMoCatch-v0", up), 1);
  EXPECT_GT(palm_normal_z(*upturned), 0.95);
  EXPECT_EQ(upturned->action_space().size(), sideways->action_space().size());
  // The ball starts above the palm: within 3 cm of the hand in x and y.
  const mjData* d = upturned->data();
  const double* hand = d->xpos + 3 * body_id(upturned->model(), "right_hand");
  const double* ball = d->xpos + 3 * body_id(upturned->model(), "target");
  EXPECT_LT(std::hypot(ball[0] - hand[0], ball[1] - hand[1]), 0.03);
  EXPECT_GT(ball[2] - hand[2], 0.15);
}

TEST(MimoSample, CatchOptionsOnOtherEnvsAreErrors) {
  SampleOptions palm_up, jitter, no_penalty;
  palm_up.palm_up = true;
  jitter.jitter = true;
  no_penalty.action_penalty = false;
  for (const SampleOptions& options : {palm_up, jitter, no_penalty}) {
    try {
      make_sample_assets("MIMoReach-v0", options);
      FAIL() << "no error for a catch option on reach";
    } catch (const UserError& e) {
      EXPECT_NE(std::string(e.what()).find("MIMoCatch-v0 only"), std::string::npos) << e.what();
    }
  }
}

TEST(MimoSample, CatchBallSizeAndMassVaryPerEpisode) {
  auto env = make_sample_env(assets("MIMoCatch-v0"), 1);
  const int geom = mj_name2id(env->model(), mjOBJ_GEOM, "target");
  const int body = body_id(env->model(), "target");
  const double r1 = env->model()->geom_size[3 * geom], m1 = env->model()->body_mass[body];
  env->reset(2);
  const double r2 = env->model()->geom_size[3 * geom], m2 = env->model()->body_mass[body];
  EXPECT_NE(r1, r2);
  EXPECT_NE(m1, m2);
  EXPECT_NEAR(env->model()->body_inertia[3 * body], 0.4 * m2 * r2 * r2, 1e-15);
  // The shared model keeps its XML ball.
  EXPECT_EQ(assets("MIMoCatch-v0")->model->geom_size[3 * geom], 0.025);
}

TEST(MimoSample, BenchAndShowroomSeeEverything) {
  for (const char* name : {"MIMoBench-v0", "MIMoShowroom-v0"}) {
    SCOPED_TRACE(name);
    auto env = make_sample_env(assets(name), 1);
    const DictSpace& space = env->observation_space();
    EXPECT_EQ(space.find("eye_left")->size(), 16 * 16 * 3);
    EXPECT_EQ(space.find("eye_right")->dtype, DType::kUInt8);
    EXPECT_NE(space.find("touch"), nullptr);
    EXPECT_NE(space.find("vestibular"), nullptr);
    EXPECT_EQ(env->action_space().size(), env->model()->nu);
    const std::vector<double> a = mid_action(*env);
    for (int i = 0; i < 3; ++i) {
      const StepResult r = env->step(a);
      EXPECT_EQ(r.reward, 0);
      EXPECT_FALSE(r.terminated);
    }
    const auto eye = env->observation().u8(env->key_index("eye_left"));
    EXPECT_GT(*std::ranges::max_element(eye), *std::ranges::min_element(eye));
  }
  EXPECT_EQ(make_sample_env(assets("MIMoBench-v0"))->model()->nu, 44);
}

}  // namespace
}  // namespace cradle::envs

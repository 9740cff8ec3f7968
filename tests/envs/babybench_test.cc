// The BabyBench env: spaces of the reference configs, proprio switches, determinism, shared
// assets, truncation and locks.
#include "envs/babybench.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <thread>

#include "core/error.h"

namespace cradle::envs {
namespace {

Config reference(const char* name) {
  return load_config(std::filesystem::path(CRADLE_SOURCE_DIR) / "configs" / name);
}

int obs_size(const BabyBenchEnv& env, const char* key) {
  const Box* box = env.observation_space().find(key);
  return box ? box->size() : -1;
}

TEST(BabyBenchEnv, ReferenceConfigSpaces) {
  struct Case {
    const char* config;
    int action, proprio;
    bool touch, vision, vestibular;
  };
  for (const Case& c : {Case{"config_test_installation.yml", 44, 292, true, true, true},
                        Case{"config_selftouch.yml", 30, 264, true, false, true},
                        Case{"config_handregard.yml", 17, 466, false, true, false}}) {
    SCOPED_TRACE(c.config);
    BabyBenchEnv env(make_assets(reference(c.config)));
    EXPECT_EQ(env.action_space().size(), c.action);
    EXPECT_EQ(env.action_space().dtype, DType::kFloat32);
    EXPECT_EQ(obs_size(env, "observation"), c.proprio);
    EXPECT_EQ(env.observation_space().find("observation")->dtype, DType::kFloat64);
    EXPECT_EQ(obs_size(env, "touch") > 0, c.touch);
    EXPECT_EQ(obs_size(env, "eye_left") == 64 * 64 * 3, c.vision);
    EXPECT_EQ(obs_size(env, "eye_right") == 64 * 64 * 3, c.vision);
    EXPECT_EQ(obs_size(env, "vestibular") == 6, c.vestibular);
    if (c.touch) {
      EXPECT_EQ(env.observation_space().find("touch")->dtype, DType::kFloat32);
      // force_vector: three values per sensor.
      EXPECT_EQ(obs_size(env, "touch"), 3 * env.touch()->sensor_count());
    }
    if (c.vision) {
      const Box* eye = env.observation_space().find("eye_left");
      EXPECT_EQ(eye->shape, (std::vector<int>{64, 64, 3}));
      EXPECT_EQ(eye->dtype, DType::kUInt8);
    }
  }
}

// Spring-damper bounds are the asymmetric force ranges (e.g. hip_bend [-1, 0.765]).
TEST(BabyBenchEnv, SpringDamperBoundsAreForceRanges) {
  BabyBenchEnv env(make_assets(reference("config_selftouch.yml")));
  EXPECT_FLOAT_EQ(env.action_space().low[0], -1);
  EXPECT_FLOAT_EQ(env.action_space().high[0], 0.765);
}

// Each proprio_* switch removes its part; with muscle/positional the actuation part is 4n / n.
TEST(BabyBenchEnv, ProprioSwitchesAndActuationSizes) {
  const Config base = reference("config_selftouch.yml");
  auto proprio_size = [](const Config& c) {
    return BabyBenchEnv(make_assets(c)).observation_space().find("observation")->size();
  };
  Config c = base;
  c.proprio_velocity = false;
  EXPECT_EQ(proprio_size(c), 264 - 47);
  c = base;
  c.proprio_torque = false;
  EXPECT_EQ(proprio_size(c), 264 - 63);
  c = base;
  c.proprio_limits = false;
  EXPECT_EQ(proprio_size(c), 264 - 47);
  c = base;
  c.proprio_actuation = false;
  EXPECT_EQ(proprio_size(c), 264 - 60);
  c = base;
  c.proprio_velocity = c.proprio_torque = c.proprio_limits = c.proprio_actuation = false;
  EXPECT_EQ(proprio_size(c), 47);

  c = base;
  c.actuation_model = ActuationModel::kMuscle;
  BabyBenchEnv muscle(make_assets(c));
  EXPECT_EQ(muscle.action_space().size(), 60);
  EXPECT_EQ(muscle.observation_space().find("observation")->size(), 324);
  c.actuation_model = ActuationModel::kPositional;
  BabyBenchEnv positional(make_assets(c));
  EXPECT_EQ(positional.action_space().size(), 30);
  EXPECT_EQ(positional.observation_space().find("observation")->size(), 234);
}

// Proprioception layout: [actuation | limits | qpos | qvel | torques]; qpos matches the data.
TEST(BabyBenchEnv, ProprioLayoutFollowsReferenceOrder) {
  BabyBenchEnv env(make_assets(reference("config_selftouch.yml")));
  env.reset(3);
  std::vector<double> action(env.action_space().size(), 0.1);
  env.step(action);
  const auto obs = env.observation().f64(env.key_index("observation"));
  const mjModel* m = env.model();
  const mjData* d = env.data();
  const int n = 30, j = 47;
  // Actuation: clipped control, then gear x control.
  EXPECT_DOUBLE_EQ(obs[0], 0.1);
  EXPECT_DOUBLE_EQ(obs[n], 0.1 * m->actuator_gear[0]);
  const int hip_lean1 = mj_name2id(m, mjOBJ_JOINT, "robot:hip_lean1");
  EXPECT_DOUBLE_EQ(obs[2 * n + j], d->qpos[m->jnt_qposadr[hip_lean1]]);
  EXPECT_DOUBLE_EQ(obs[2 * n + 2 * j], d->qvel[m->jnt_dofadr[hip_lean1]]);
  const int neck = mj_name2id(m, mjOBJ_SENSOR, "proprio:neck");
  EXPECT_DOUBLE_EQ(obs[2 * n + 3 * j], d->sensordata[m->sensor_adr[neck]]);
}

std::vector<std::byte> snapshot(const BabyBenchEnv& env) {
  std::vector<std::byte> out;
  for (int i = 0; i < env.observation().count(); ++i) {
    const auto b = env.observation().bytes(i);
    out.insert(out.end(), b.begin(), b.end());
  }
  return out;
}

// Same seed => bitwise-identical observations for 1,000 steps, in two envs sharing one set of
// assets and in an env built from separately compiled assets.
TEST(BabyBenchEnv, SeededRunsAreBitwiseIdentical) {
  const Config config = reference("config_selftouch.yml");
  const auto shared = make_assets(config);
  BabyBenchEnv a(shared), b(shared), c(make_assets(config));
  for (BabyBenchEnv* env : {&a, &b, &c}) env->reset(42);
  Rng policy(7);
  std::vector<double> action(a.action_space().size());
  for (int t = 0; t < 1000; ++t) {
    for (size_t k = 0; k < action.size(); ++k) {
      action[k] = policy.uniform(a.action_space().low[k], a.action_space().high[k]);
    }
    a.step(action);
    b.step(action);
    c.step(action);
    const auto sa = snapshot(a);
    ASSERT_EQ(sa, snapshot(b)) << "step " << t;
    ASSERT_EQ(sa, snapshot(c)) << "step " << t;
  }
  // A different seed gives a different start.
  BabyBenchEnv d(shared);
  d.reset(43);
  a.reset(42);
  EXPECT_NE(snapshot(a), snapshot(d));
  // Reseeding reproduces the start exactly.
  b.reset(42);
  EXPECT_EQ(snapshot(a), snapshot(b));
}

// A curriculum's start posture: 0 is the plain start, larger shares move the start further, and
// values outside [0, 1] are refused.
TEST(BabyBenchEnv, StartPostureRangeScalesTheStartDraw) {
  const auto shared = make_assets(reference("config_selftouch.yml"));
  BabyBenchEnv env(shared);
  auto start = [&](double range) {
    env.set_reset_options({{"start_posture_range", range}});
    env.reset(5);
    return std::vector<double>(env.data()->qpos, env.data()->qpos + env.model()->nq);
  };
  auto distance = [](const std::vector<double>& a, const std::vector<double>& b) {
    double sum = 0;
    for (size_t i = 0; i < a.size(); ++i) sum += std::abs(a[i] - b[i]);
    return sum;
  };
  BabyBenchEnv plain(shared);
  plain.reset(5);
  const std::vector<double> q0(plain.data()->qpos, plain.data()->qpos + plain.model()->nq);
  EXPECT_EQ(start(0), q0);
  const double small = distance(start(0.1), q0), whole = distance(start(1), q0);
  EXPECT_GT(small, 0);
  EXPECT_GT(whole, 3 * small);
  EXPECT_THROW(env.set_reset_options({{"start_posture_range", 1.5}}), UserError);
  EXPECT_THROW(env.set_reset_options({{"start_posture", 0.5}}), UserError);
}

// Two envs stepped on two threads give the results of one thread: no shared mutable state.
TEST(BabyBenchEnv, EnvsOnTwoThreadsMatch) {
  const auto shared = make_assets(reference("config_selftouch.yml"));
  auto run = [&](std::vector<std::byte>& out) {
    BabyBenchEnv env(shared);
    env.reset(5);
    std::vector<double> action(env.action_space().size(), 0.3);
    for (int t = 0; t < 300; ++t) env.step(action);
    out = snapshot(env);
  };
  std::vector<std::byte> x, y, z;
  std::thread t1(run, std::ref(x)), t2(run, std::ref(y));
  t1.join();
  t2.join();
  run(z);
  EXPECT_EQ(x, z);
  EXPECT_EQ(y, z);
}

TEST(BabyBenchEnv, TruncatesAtMaxEpisodeStepsAndCountsSteps) {
  Config config = reference("config_selftouch.yml");
  config.max_episode_steps = 25;
  BabyBenchEnv env(make_assets(config));
  env.reset(1);
  std::vector<double> zero(env.action_space().size(), 0.0);
  for (int t = 0; t < 25; ++t) {
    const StepResult r = env.step(zero);
    EXPECT_EQ(env.info().steps, t);
    EXPECT_EQ(r.reward, 0);
    EXPECT_FALSE(r.terminated);
    EXPECT_EQ(r.truncated, t == 24);
  }
}

// Config locks are active from construction: the settled start already holds them, zero-action
// steps keep them within 1e-3 rad from the first step, and full random effort (locked feet pushed
// by their own actuators, every other joint thrashing) moves them by at most 2e-3 rad.
TEST(BabyBenchEnv, LocksHoldFromTheFirstStep) {
  Config config = reference("config_test_installation.yml");  // feet locked and actuated
  config.vision_active = false;
  const auto assets = make_assets(config);
  const mjModel* m = assets->model.get();
  std::vector<int> locked;
  for (int i = 0; i < m->neq; ++i) {
    if (m->eq_type[i] == mjEQ_JOINT && m->eq_active[i]) locked.push_back(m->eq_obj1id[i]);
  }
  ASSERT_EQ(locked.size(), 8u);
  for (int j : locked) EXPECT_NEAR(assets->settled.qpos[m->jnt_qposadr[j]], 0, 1e-4);

  auto worst_error = [&](BabyBenchEnv& env) {
    double worst = 0;
    for (int j : locked) worst = std::max(worst, std::abs(env.data()->qpos[m->jnt_qposadr[j]]));
    return worst;
  };
  BabyBenchEnv quiet(assets);
  std::vector<double> zero(quiet.action_space().size(), 0.0);
  for (int t = 0; t < 200; ++t) {
    quiet.step(zero);
    ASSERT_LT(worst_error(quiet), 1e-3) << "step " << t;
  }

  BabyBenchEnv env(assets);
  env.reset(9);
  Rng policy(2);
  std::vector<double> action(env.action_space().size());
  for (int t = 0; t < 500; ++t) {
    for (size_t k = 0; k < action.size(); ++k) {
      action[k] = policy.uniform(env.action_space().low[k], env.action_space().high[k]);
    }
    env.step(action);
    ASSERT_LT(worst_error(env), 2e-3) << "step " << t;
  }
}

}  // namespace
}  // namespace cradle::envs

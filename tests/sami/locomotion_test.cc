// Locomotion envs: hidden parameters on private arrays, crippling, determinism, errors and a
// scripted gait.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "core/error.h"
#include "sami/env.h"

namespace cradle::sami {
namespace {

std::vector<double> copy(const mjtNum* p, int n) { return std::vector<double>(p, p + n); }

TEST(SamiLocomotion, MassFactorTwoDoublesEveryMassOnThePrivateModelOnly) {
  for (EnvId id : {EnvId::kHalfCheetah, EnvId::kHopper, EnvId::kWalker, EnvId::kSlimHumanoid,
                   EnvId::kCrippleAnt}) {
    auto env = make_env(id, {{.mass = {2.0}}}, 1);
    const mjModel* shared = env->shared_model();
    const std::vector<double> before = copy(shared->body_mass, shared->nbody);
    env->reset(3);
    EXPECT_EQ(env->info().mass, 2.0);
    for (int b = 0; b < shared->nbody; ++b) {
      EXPECT_DOUBLE_EQ(env->model()->body_mass[b], 2.0 * before[b]) << env_name(id) << b;
      EXPECT_DOUBLE_EQ(shared->body_mass[b], before[b]);
      // Inertia is not scaled (as in SaMI).
      EXPECT_EQ(env->model()->body_inertia[3 * b], shared->body_inertia[3 * b]);
    }
  }
}

TEST(SamiLocomotion, DampingFactorScalesDofDampingWithoutAccumulating) {
  auto env = make_env(EnvId::kHalfCheetah, {{.damping = {1.5}}}, 1);
  const mjModel* shared = env->shared_model();
  for (int episode = 0; episode < 3; ++episode) {
    env->reset();
    for (int v = 0; v < shared->nv; ++v) {
      EXPECT_DOUBLE_EQ(env->model()->dof_damping[v], 1.5 * shared->dof_damping[v]);
    }
  }
  EXPECT_DOUBLE_EQ(shared->dof_damping[3], 6.0);
}

TEST(SamiLocomotion, AntSplitsBodiesAndDofsDifferently) {
  // Damping x2 (factors are at most 3: validate() in sami/task.h).
  auto env = make_env(EnvId::kAnt, {{.mass = {2.0}, .damping = {2.0}}}, 1);
  env->reset(0);
  const mjModel* s = env->shared_model();
  const mjModel* m = env->model();
  EXPECT_DOUBLE_EQ(m->body_mass[1], s->body_mass[1]);  // torso unchanged
  for (int b = 2; b < 8; ++b) EXPECT_DOUBLE_EQ(m->body_mass[b], 2 * s->body_mass[b]);
  for (int b = 8; b < 14; ++b) EXPECT_DOUBLE_EQ(m->body_mass[b], s->body_mass[b] / 2);
  // Dofs: leg 1 (6, 7) times d; legs 2-4 (8..13) divided by d.
  EXPECT_DOUBLE_EQ(m->dof_damping[6], 2.0);
  EXPECT_DOUBLE_EQ(m->dof_damping[7], 2.0);
  for (int v = 8; v < 14; ++v) EXPECT_DOUBLE_EQ(m->dof_damping[v], 0.5);
}

TEST(SamiLocomotion, CrippledActuatorHasNoEffectOnTheNextState) {
  for (EnvId id : {EnvId::kCrippleHalfCheetah, EnvId::kCrippleHopper, EnvId::kCrippleWalker,
                   EnvId::kWalkerHopper}) {
    auto env = make_env(id, {{.cripple = {{1}}}}, 1);
    const int n = env->spec().action_size;
    auto next_state = [&](int changed) {
      env->reset(7);
      std::vector<double> a(n, 0.5);
      if (changed >= 0) a[changed] = -0.9;
      env->step(a);
      return copy(env->data()->qpos, env->model()->nq);
    };
    const std::vector<double> base = next_state(-1);
    EXPECT_EQ(next_state(1), base) << env_name(id);  // the crippled joint
    EXPECT_NE(next_state(0), base) << env_name(id);  // a healthy one
    EXPECT_EQ(env->info().crippled, std::vector<int>{1});
    EXPECT_TRUE(env->info().masked);
  }
}

TEST(SamiLocomotion, CrippledAntLegHasHalfSizeCapsulesAndNoTorque) {
  auto env = make_env(EnvId::kCrippleAnt, {{.cripple = {{2}}}}, 1);
  env->reset(5);
  const mjModel* s = env->shared_model();
  const mjModel* m = env->model();
  for (int g = 0; g < s->ngeom; ++g) {
    const bool crippled = g == 9 || g == 10;  // leg 2 (-x -y): thigh and lower leg
    for (int i = 0; i < 2; ++i) {
      EXPECT_DOUBLE_EQ(m->geom_size[3 * g + i], (crippled ? 0.5 : 1.0) * s->geom_size[3 * g + i]);
    }
    EXPECT_EQ(m->geom_rgba[4 * g + 1] == 0, crippled) << g;
  }
  EXPECT_DOUBLE_EQ(m->geom_size[3 * 9], 0.04);
  // Actuators 6, 7 (hip_3, ankle_3) are masked.
  std::vector<double> a(8, 0.3);
  env->step(a);
  EXPECT_EQ(env->data()->ctrl[6], 0.0);
  EXPECT_EQ(env->data()->ctrl[7], 0.0);
  EXPECT_EQ(env->data()->ctrl[0], static_cast<float>(0.3));  // the float32 action
  // The shared model keeps its sizes and colours.
  EXPECT_DOUBLE_EQ(s->geom_size[3 * 9], 0.08);
}

TEST(SamiLocomotion, WalkerHopperModeThreeShrinksWithoutMasking) {
  auto env = make_env(EnvId::kWalkerHopper, {{.cripple = {{0, 1, 2}}, .mask = false}}, 1);
  env->reset(2);
  EXPECT_FALSE(env->info().masked);
  EXPECT_DOUBLE_EQ(env->model()->geom_size[3 * 2], 0.025);  // right thigh r 0.05 -> 0.025
  EXPECT_DOUBLE_EQ(env->model()->geom_size[3 * 3 + 1], 0.125);
  std::vector<double> a(6, 0.4);
  env->step(a);
  EXPECT_EQ(env->data()->ctrl[0], static_cast<float>(0.4));  // the float32 action
}

TEST(SamiLocomotion, SeededResetsAndStepsAreDeterministic) {
  for (EnvId id : {EnvId::kHalfCheetah, EnvId::kAnt, EnvId::kHumanoidStandup, EnvId::kCrippleAnt}) {
    auto run = [&] {
      auto env = make_env(id, split_sets(id, Split::kTrain), 11);
      std::vector<double> trace;
      for (int episode = 0; episode < 2; ++episode) {
        env->reset(episode == 0 ? std::optional<std::uint64_t>(42) : std::nullopt);
        trace.push_back(env->info().mass);
        trace.push_back(env->info().damping);
        std::vector<double> a(env->spec().action_size);
        for (int t = 0; t < 20; ++t) {
          for (size_t i = 0; i < a.size(); ++i) a[i] = std::sin(0.3 * t + static_cast<double>(i));
          trace.push_back(env->step(a).reward);
        }
        const auto obs = env->observation();
        trace.insert(trace.end(), obs.begin(), obs.end());
      }
      return trace;
    };
    EXPECT_EQ(run(), run()) << env_name(id);
  }
}

TEST(SamiLocomotion, SpecsMatchTheReference) {
  struct Row {
    EnvId id;
    int obs, act, horizon;
  };
  const Row rows[] = {{EnvId::kHalfCheetah, 18, 6, 1000},   {EnvId::kAnt, 28, 8, 2000},
                      {EnvId::kHopper, 11, 3, 2000},        {EnvId::kWalker, 17, 6, 2000},
                      {EnvId::kSlimHumanoid, 45, 17, 1000}, {EnvId::kHumanoidStandup, 45, 17, 2000},
                      {EnvId::kCrippleAnt, 41, 8, 2000},    {EnvId::kCrippleHopper, 11, 3, 1000},
                      {EnvId::kWalkerHopper, 17, 6, 2000},  {EnvId::kPandaPush, 25, 4, 50}};
  for (const Row& r : rows) {
    auto env = make_env(r.id, split_sets(r.id, Split::kTrain), 0);
    EXPECT_EQ(env->spec().obs_size, r.obs) << env_name(r.id);
    EXPECT_EQ(env->spec().action_size, r.act);
    EXPECT_EQ(env->spec().horizon, r.horizon);
    env->reset(0);
    std::vector<double> a(r.act, 0.0);
    StepResult out;
    int steps = 0;
    // No early termination for locomotion: only the horizon ends an episode (checked on the
    // cheap envs; every env shares the same step code).
    if (r.id == EnvId::kHalfCheetah || r.id == EnvId::kCrippleHopper) {
      do {
        out = env->step(a);
        ++steps;
      } while (!out.truncated && !out.terminated && steps < r.horizon + 1);
      EXPECT_EQ(steps, r.horizon);
      EXPECT_FALSE(out.terminated);
    }
  }
}

TEST(SamiLocomotion, BadNamesSplitsAndValuesAreOneLineErrors) {
  auto message = [](auto&& f) {
    try {
      f();
    } catch (const UserError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message([] { make_env("Cheetah", "train", 0); }).find("unknown SaMI env 'Cheetah'"),
            std::string::npos);
  EXPECT_NE(message([] { make_env("Ant", "hard", 0); }).find("unknown split 'hard'"),
            std::string::npos);
  EXPECT_NE(message([] { make_env(EnvId::kAnt, {{.mass = {-1.0}}}, 0); }).find("mass factor"),
            std::string::npos);
  EXPECT_NE(message([] {
              make_env(EnvId::kCrippleAnt, {{.damping = {2.0}}}, 0);
            }).find("does not vary damping"),
            std::string::npos);
  EXPECT_NE(
      message([] { make_env(EnvId::kCrippleAnt, {{.cripple = {{4}}}}, 0); }).find("out of range"),
      std::string::npos);
  EXPECT_NE(
      message([] { make_env(EnvId::kHopper, {{.cripple = {{0}}}}, 0); }).find("cannot be crippled"),
      std::string::npos);
  EXPECT_NE(message([] { make_env(EnvId::kPandaPush, {{}}, 0); }).find("no cells"),
            std::string::npos);
  auto env = make_env(EnvId::kHopper, {{}}, 0);
  env->reset(0);
  EXPECT_NE(message([&] { env->step(std::vector<double>(2)); }).find("expected 3"),
            std::string::npos);
  for (const std::string& m : {message([] { make_env("Cheetah", "train", 0); })}) {
    EXPECT_EQ(m.find('\n'), std::string::npos);
  }
}

// Distance travelled by Half-Cheetah under an open-loop gait in 200 steps (10 s) from a seeded
// reset.
double gait_distance(double mass, std::uint64_t seed, double* episode_return) {
  auto env = make_env(EnvId::kHalfCheetah, {{.mass = {mass}, .damping = {1.0}}}, 3);
  env->reset(seed);
  std::vector<double> a(6);
  double ret = 0;
  for (int t = 0; t < 200; ++t) {
    const double phase = 2 * M_PI * 2.0 * t * env->spec().dt;  // 2 Hz
    for (int i = 0; i < 6; ++i) a[i] = std::sin(phase + (i < 3 ? 0.0 : M_PI) + 0.5 * (i % 3));
    ret += env->step(a).reward;
  }
  if (episode_return) *episode_return = ret;
  return env->data()->qpos[0];
}

TEST(SamiLocomotion, OpenLoopGaitMovesAHeavyHalfCheetahForwardFromEveryStart) {
  // At mass x1 this gait is chaotic (a 1e-6 change of the action moves the end point by metres,
  // forwards or backwards); at x3 the cheetah stays upright and runs forward from every start.
  double total_return = 0;
  for (std::uint64_t seed = 0; seed < 20; ++seed) {
    double ret = 0;
    EXPECT_GT(gait_distance(3.0, seed, &ret), 3.0) << seed;
    total_return += ret;
  }
  EXPECT_GT(total_return / 20, 0.0);
}

}  // namespace
}  // namespace cradle::sami

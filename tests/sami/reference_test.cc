// The locomotion envs against SaMI's own env classes (uoe-agents/SaMI envs/*.py on gym 0.23 and
// NumPy 1.x): each step's reward recomputed here from the env's state with the reference's formula
// and its float32 roundings, the reset's order, Ant's reciprocal factor, and golden digests of the
// compiled models and of seeded 1,000-step trajectories.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "core/rng.h"
#include "sami/env.h"

namespace cradle::sami {
namespace {

// np.sum of a contiguous array as NumPy 1.x adds it up (pairwise: eight running sums for 8..128
// values, combined as a tree; a plain running sum below 8).
template <class T>
T np_sum(const std::vector<T>& x) {
  const size_t n = x.size();
  if (n < 8) {
    T s = 0;
    for (T v : x) s += v;
    return s;
  }
  EXPECT_LE(n, 128u);  // the envs' arrays; NumPy splits longer ones in halves
  T r[8];
  for (int j = 0; j < 8; ++j) r[j] = x[j];
  size_t i = 8;
  for (; i < n - n % 8; i += 8) {
    for (int j = 0; j < 8; ++j) r[j] += x[i + j];
  }
  T s = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]));
  for (; i < n; ++i) s += x[i];
  return s;
}

// np.square(x).sum() on a float32 array: squares and sum in float32.
double f32_square_sum(const std::vector<float>& a) {
  std::vector<float> sq;
  for (float v : a) sq.push_back(v * v);
  return np_sum(sq);
}

double f64_square_sum(const std::vector<double>& a) {
  std::vector<double> sq;
  for (double v : a) sq.push_back(v * v);
  return np_sum(sq);
}

bool crippled_env(EnvId id) {
  return id == EnvId::kCrippleHalfCheetah || id == EnvId::kCrippleAnt ||
         id == EnvId::kCrippleHopper || id == EnvId::kCrippleWalker || id == EnvId::kWalkerHopper;
}

// What the reference reads before a step: gym's prev_qpos / posbefore (root x), AntEnv's
// xposbefore (the torso's xpos as the last mj_step left it) and the float32 observation.
struct Before {
  double root_x, torso_x;
  std::vector<float> obs;
};

// The reference's reward of the step just taken, from the env's state after it. `a32` is the
// action as the reference's agents pass it (float32).
double reference_reward(const SamiEnv& env, const Before& b, const std::vector<float>& a32) {
  const EnvId id = env.spec().id;
  const mjModel* m = env.model();
  const mjData* d = env.data();
  const std::span<const float> obs = env.observation();
  // The crippled envs multiply the action by a float64 mask (np.ones), so their action and its
  // square sum are float64; the others square and sum the float32 action.
  std::vector<double> masked(a32.begin(), a32.end());
  const std::span<const double> mask = env.action_mask();
  if (crippled_env(id)) {
    for (size_t i = 0; i < masked.size(); ++i) masked[i] = mask[i] * masked[i];
  }
  const double sq = crippled_env(id) ? f64_square_sum(masked) : f32_square_sum(a32);
  std::vector<double> ctrl(d->ctrl, d->ctrl + m->nu);
  std::vector<double> cfrc(d->cfrc_ext, d->cfrc_ext + 6 * m->nbody);
  switch (id) {
    case EnvId::kHalfCheetah:
    case EnvId::kCrippleHalfCheetah: {
      // reward_run = ob['observation'][0] (float32), reward_ctrl = -0.1 * sum.
      const double dt = m->opt.timestep * 5;
      EXPECT_EQ(obs[0], static_cast<float>((d->qpos[0] - b.root_x) / dt));
      return static_cast<double>(obs[0]) + -0.1 * sq;
    }
    case EnvId::kAnt:
    case EnvId::kCrippleAnt: {
      const double dt = m->opt.timestep * 5;
      const double run = (d->xpos[3] - b.torso_x) / dt;
      if (id == EnvId::kAnt) {
        EXPECT_EQ(obs[0], static_cast<float>(run));
      }
      std::vector<double> contact;
      for (double f : cfrc) contact.push_back(std::clamp(f, -1.0, 1.0));
      return run + -0.01 * sq + -0.5 * f64_square_sum(contact) + 1.0;
    }
    case EnvId::kHopper:
    case EnvId::kWalker:
    case EnvId::kCrippleHopper:
    case EnvId::kCrippleWalker:
    case EnvId::kWalkerHopper: {
      double r = (d->qpos[0] - b.root_x) / (m->opt.timestep * 4);
      r += 1.0;
      r -= (id == EnvId::kHopper ? 1e-1 : 1e-3) * sq;
      return r;
    }
    case EnvId::kSlimHumanoid: {
      // lin_vel_cost = 0.25 / 0.015 * old_obs[22] (qvel[0] before the step, float32).
      const double lin_vel = 0.25 / 0.015 * static_cast<double>(b.obs[22]);
      const double quad_ctrl = 0.1 * f64_square_sum(ctrl);
      const bool done = d->qpos[2] < 1.0 || d->qpos[2] > 2.0;
      const double alive = 5.0 * (1 - static_cast<double>(done));
      return lin_vel - quad_ctrl - 0.0 + alive;
    }
    case EnvId::kHumanoidStandup: {
      const double uph = (d->qpos[2] - 0) / m->opt.timestep;
      const double quad_ctrl = 0.1 * f64_square_sum(ctrl);
      const double impact = std::min(0.5e-6 * f64_square_sum(cfrc), 10.0);
      return uph - quad_ctrl - impact + 1;
    }
    case EnvId::kPandaPush:
      break;
  }
  ADD_FAILURE() << "not a locomotion env";
  return 0;
}

// Steps an env with uniform random actions (doubles that float32 cannot hold, so the rounding is
// exercised) and requires every reward to equal the reference's bit for bit.
void expect_reference_rewards(EnvId id, const std::vector<TaskSet>& sets, int steps,
                              Options options = {}, double start_height = 0) {
  auto env = make_env(id, sets, 3, nullptr, options);
  const Spec& spec = env->spec();
  Rng rng(17);
  std::vector<double> a(spec.action_size);
  std::vector<float> a32(spec.action_size);
  int alive_steps = 0, nonzero_contacts = 0;
  for (int t = 0; t < steps; ++t) {
    if (t % 100 == 0) {
      env->reset(t / 100 + 1);
      if (start_height > 0) {
        // A humanoid lifted into the alive band [1, 2] m falls through it: both branches of the
        // alive bonus are taken.
        env->data()->qpos[2] = start_height;
        mj_forward(env->model(), env->data());
      }
    }
    for (int i = 0; i < spec.action_size; ++i) {
      a[i] = rng.uniform(spec.action_low, spec.action_high);
      a32[i] = static_cast<float>(a[i]);
    }
    const Before before{env->data()->qpos[0], env->data()->xpos[3],
                        std::vector<float>(env->observation().begin(), env->observation().end())};
    const double reward = env->step(a).reward;
    const double expected = reference_reward(*env, before, a32);
    ASSERT_EQ(reward, expected) << env_name(id) << " step " << t << " differs by "
                                << reward - expected;
    // The actuators see the float32 action times the mask.
    for (int i = 0; i < spec.action_size; ++i) {
      const double mask = env->action_mask().empty() ? 1.0 : env->action_mask()[i];
      ASSERT_EQ(env->data()->ctrl[i], mask * static_cast<double>(a32[i]));
    }
    if (env->data()->qpos[2] >= 1.0 && env->data()->qpos[2] <= 2.0) ++alive_steps;
    for (int i = 0; i < 6 * env->model()->nbody; ++i)
      nonzero_contacts += env->data()->cfrc_ext[i] != 0;
  }
  if (start_height > 0) {
    EXPECT_GT(alive_steps, 0) << env_name(id);
    EXPECT_LT(alive_steps, steps) << env_name(id);
  }
  if (options.contact_forces) {
    EXPECT_GT(nonzero_contacts, 0) << env_name(id);
  }
}

TEST(SamiReference, EveryLocomotionRewardIsTheReferenceFormulaBitForBit) {
  for (EnvId id : all_envs()) {
    if (id == EnvId::kPandaPush) continue;
    // CrippleHopper cripples only in its extreme split.
    const Split split = id == EnvId::kCrippleHopper ? Split::kExtreme : Split::kTrain;
    const int steps = id == EnvId::kSlimHumanoid || id == EnvId::kHumanoidStandup ? 200 : 300;
    expect_reference_rewards(id, split_sets(id, split), steps);
  }
}

TEST(SamiReference, ContactCostsFollowTheReferenceWhenContactForcesAreOn) {
  // cfrc_ext filled: the Ant's clipped contact cost and HumanoidStandup's impact cost act.
  for (EnvId id : {EnvId::kAnt, EnvId::kCrippleAnt, EnvId::kHumanoidStandup}) {
    expect_reference_rewards(id, split_sets(id, Split::kTrain), 200, {.contact_forces = true});
  }
}

TEST(SamiReference, SlimHumanoidPaysTheAliveBonusOnlyBetweenOneAndTwoMetres) {
  expect_reference_rewards(EnvId::kSlimHumanoid, split_sets(EnvId::kSlimHumanoid, Split::kTrain),
                           200, {}, 1.5);
}

TEST(SamiReference, SlimHumanoidForwardTermIsTheStartVelocityTimesFiftyThirds) {
  // From rest with the root pushed at 1 m/s along x and no action, the reward is 0.25 / 0.015
  // times float32(1.0): the pre-step velocity, not the displacement over the step.
  auto env = make_env(EnvId::kSlimHumanoid, {{}}, 0);
  env->reset(0);
  env->data()->qvel[0] = 1.0;
  const std::vector<double> zero(17, 0.0);
  const double reward = env->step(zero).reward;
  EXPECT_EQ(reward, 0.25 / 0.015);
  EXPECT_EQ(env->info().x_velocity, 1.0);
}

TEST(SamiReference, AntLegsThreeAndFourGetTheReciprocalTimesTheMass) {
  // AntEnv multiplies by 1.0 / m; for these factors that differs from dividing in the last bit
  // of some masses, so this test tells the two apart.
  int differ = 0;
  for (double f : {0.2, 0.4, 1.25, 1.6}) {
    auto env = make_env(EnvId::kAnt, {{.mass = {f}, .damping = {f}}}, 1);
    env->reset(0);
    const mjModel* s = env->shared_model();
    const mjModel* m = env->model();
    for (int i = 8; i < 14; ++i) {
      EXPECT_EQ(m->body_mass[i], s->body_mass[i] * (1.0 / f)) << f << " body " << i;
      EXPECT_EQ(m->dof_damping[i], s->dof_damping[i] * (1.0 / f)) << f << " dof " << i;
      differ += s->body_mass[i] * (1.0 / f) != s->body_mass[i] / f;
    }
  }
  EXPECT_GT(differ, 0);
}

TEST(SamiReference, ResetForwardStillSeesTheLastEpisodesParameters) {
  // gym's set_state runs mj_forward before change_env writes the new masses: the mass matrix the
  // reset leaves (and the first step's warm start) comes from the previous episode's masses.
  // Half-Cheetah's rootx entry of the mass matrix is the total mass.
  auto env = make_env(EnvId::kHalfCheetah, {{.mass = {2.0}}}, 1);
  const mjModel* s = env->shared_model();
  double total = 0;
  for (int b = 0; b < s->nbody; ++b) total += s->body_mass[b];
  env->reset(0);
  EXPECT_NEAR(env->data()->qM[0], total, 1e-9);  // the model's own masses
  EXPECT_DOUBLE_EQ(env->model()->body_mass[1], 2 * s->body_mass[1]);
  env->reset();
  EXPECT_NEAR(env->data()->qM[0], 2 * total, 1e-9);  // the first episode's
}

// FNV-1a over bytes.
std::uint64_t fnv(std::uint64_t h, const void* p, size_t n) {
  const auto* c = static_cast<const unsigned char*>(p);
  for (size_t i = 0; i < n; ++i) h = (h ^ c[i]) * 0x100000001b3ull;
  return h;
}
constexpr std::uint64_t kFnvBasis = 0xcbf29ce484222325ull;

// The compiled numbers that shape the dynamics.
std::uint64_t model_digest(const mjModel* m) {
  std::uint64_t h = kFnvBasis;
  auto add = [&](const mjtNum* p, int n) { h = fnv(h, p, sizeof(mjtNum) * n); };
  add(m->body_mass, m->nbody);
  add(m->body_inertia, 3 * m->nbody);
  add(m->body_pos, 3 * m->nbody);
  add(m->body_quat, 4 * m->nbody);
  add(m->body_ipos, 3 * m->nbody);
  add(m->body_iquat, 4 * m->nbody);
  add(m->jnt_pos, 3 * m->njnt);
  add(m->jnt_axis, 3 * m->njnt);
  add(m->jnt_range, 2 * m->njnt);
  add(m->jnt_stiffness, m->njnt);
  add(m->dof_damping, m->nv);
  add(m->dof_armature, m->nv);
  add(m->geom_size, 3 * m->ngeom);
  add(m->geom_pos, 3 * m->ngeom);
  add(m->geom_quat, 4 * m->ngeom);
  add(m->geom_friction, 3 * m->ngeom);
  add(m->actuator_gear, 6 * m->nu);
  add(m->actuator_ctrlrange, 2 * m->nu);
  add(m->qpos0, m->nq);
  add(&m->opt.timestep, 1);
  return h;
}

struct Outcome {
  std::uint64_t state;  // qpos and qvel bytes after the last step
  double ret;           // the sum of the rewards
};

// 1,000 steps from a seeded reset of the train split (its mass and damping draw included), with
// zero actions or a sinusoid per actuator.
Outcome trajectory(EnvId id, bool sinusoid) {
  auto env = make_env(id, split_sets(id, Split::kTrain), 5);
  env->reset(5);
  const Spec& spec = env->spec();
  std::vector<double> a(spec.action_size, 0.0);
  double ret = 0;
  for (int t = 0; t < 1000; ++t) {
    if (sinusoid) {
      for (int i = 0; i < spec.action_size; ++i) {
        a[i] = 0.8 * spec.action_high * std::sin(0.2 * t + 0.7 * i);
      }
    }
    ret += env->step(a).reward;
  }
  const mjModel* m = env->model();
  std::uint64_t h = fnv(kFnvBasis, env->data()->qpos, sizeof(mjtNum) * m->nq);
  return {fnv(h, env->data()->qvel, sizeof(mjtNum) * m->nv), ret};
}

std::string hex(std::uint64_t v) {
  char buf[20];
  std::snprintf(buf, sizeof(buf), "%016llx", static_cast<unsigned long long>(v));
  return buf;
}

TEST(SamiReference, CompiledModelsAndTrajectoriesMatchTheirGoldenDigests) {
  // A change here changes every SaMI result on these envs: re-run the comparison with the
  // reference (docs/fidelity.md) before updating a digest. The Hopper and Walker model digests
  // are those of gym's own hopper.xml and walker2d.xml compiled by MuJoCo 2.2.2.
  struct Golden {
    EnvId id;
    const char* model;
    const char* zero;
    const char* sine;
  };
  const Golden golden[] = {
      {EnvId::kHalfCheetah, "131e4dc4254be7d7", "e9f488df48e136cc", "57ac5244de44760a"},
      {EnvId::kAnt, "ddf202c3a6ce2373", "178c72bb99be32f5", "75099ae1614b014e"},
      {EnvId::kHumanoidStandup, "ab7d16a39d4306ab", "aa8cfd0365e609b3", "de2fc128996511ab"},
      {EnvId::kHopper, "437c3874caf413e7", "698db6ca2471c168", "e784cee13fb56b81"},
      {EnvId::kWalker, "143ee7738608a231", "e265b74a18ca3997", "a330102b5f9c8d71"},
  };
  for (const Golden& g : golden) {
    auto env = make_env(g.id, split_sets(g.id, Split::kTrain), 0);
    EXPECT_EQ(hex(model_digest(env->shared_model())), g.model) << env_name(g.id);
    const Outcome zero = trajectory(g.id, false), sine = trajectory(g.id, true);
    EXPECT_EQ(hex(zero.state), g.zero) << env_name(g.id) << " zero-action return " << zero.ret;
    EXPECT_EQ(hex(sine.state), g.sine) << env_name(g.id) << " sinusoid return " << sine.ret;
    // Deterministic: the same run twice gives the same bits.
    EXPECT_EQ(trajectory(g.id, true).state, sine.state);
  }
}

}  // namespace
}  // namespace cradle::sami

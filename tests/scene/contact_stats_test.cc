// Contact statistics of the compiled reference scenes against the reference's:
// mean contacts and constraint rows per step over the first 1,000 zero-action env steps after
// reset(0), within 5 %. The reference kit is not installed here, so the numbers below come from
// the reference-equivalent scenes: our composition with the reference's crib mattress (friction
// 0.1, no contact priority, MuJoCo's default solver parameters: spec babybench_layer.md §2.6),
// which is the default; the body, joints, actuators and options match the kit's to 6 digits.
// Recorded with MuJoCo 2.2.2 by this test's own measure() (docs/
// babybench-physics.md). The opt-in low-friction mattress must stay a different task: more of its
// contacts slide.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/config.h"
#include "envs/babybench.h"

namespace cradle {
namespace {

struct ContactStats {
  double contacts = 0;     // mean d->ncon per env step
  double constraints = 0;  // mean d->nefc per env step
  double sliding = 0;      // mean contacts per step whose friction force is at the cone's edge
};

// The first `steps` zero-action env steps after reset(0), vision off (physics only).
ContactStats measure(const char* file, bool mattress_friction_applies = false, int steps = 1000) {
  Config config = load_config(std::string(CRADLE_SOURCE_DIR) + "/configs/" + file);
  config.vision_active = false;
  config.mattress_friction_applies = mattress_friction_applies;
  envs::BabyBenchEnv env(envs::make_assets(config), 0);
  env.reset(0);
  const std::vector<double> zero(env.action_space().size(), 0.0);
  ContactStats s;
  for (int t = 0; t < steps; ++t) {
    env.step(zero);
    const mjModel* m = env.model();
    const mjData* d = env.data();
    s.contacts += d->ncon;
    s.constraints += d->nefc;
    for (int i = 0; i < d->ncon; ++i) {
      const mjContact& c = d->contact[i];
      if (c.dim < 3 || c.exclude) continue;
      mjtNum f[6];
      mj_contactForce(m, d, i, f);
      s.sliding += f[0] > 0 && std::hypot(f[1], f[2]) >= 0.99 * c.friction[0] * f[0];
    }
  }
  s.contacts /= steps;
  s.constraints /= steps;
  s.sliding /= steps;
  return s;
}

void expect_within(double measured, double reference, double tolerance, const char* what) {
  EXPECT_NEAR(measured, reference, tolerance * reference)
      << what << ": " << measured << " against the reference's " << reference;
}

// Recorded from the reference-equivalent scenes (see the header).
constexpr ContactStats kCribReference = {
    .contacts = 9.376, .constraints = 96.940, .sliding = 1.491};
constexpr ContactStats kCubesReference = {
    .contacts = 68.205, .constraints = 313.163, .sliding = 0.744};

TEST(ContactStats, CribMatchesTheReference) {
  const ContactStats s = measure("config_selftouch.yml");
  std::printf("crib: %.3f contacts, %.3f constraints, %.3f sliding per step\n", s.contacts,
              s.constraints, s.sliding);
  expect_within(s.contacts, kCribReference.contacts, 0.05, "crib contacts per step");
  expect_within(s.constraints, kCribReference.constraints, 0.05, "crib constraints per step");
}

TEST(ContactStats, CubesMatchTheReference) {
  const ContactStats s = measure("config_handregard.yml");
  std::printf("cubes: %.3f contacts, %.3f constraints, %.3f sliding per step\n", s.contacts,
              s.constraints, s.sliding);
  expect_within(s.contacts, kCubesReference.contacts, 0.05, "cubes contacts per step");
  expect_within(s.constraints, kCubesReference.constraints, 0.05, "cubes constraints per step");
}

TEST(ContactStats, LowFrictionMattressIsAnotherTask) {
  const ContactStats& reference = kCribReference;
  const ContactStats low = measure("config_selftouch.yml", /*mattress_friction_applies=*/true);
  std::printf("crib, mattress friction applies: %.3f contacts, %.3f constraints, %.3f sliding\n",
              low.contacts, low.constraints, low.sliding);
  EXPECT_GT(low.sliding, reference.sliding + 2);
}

}  // namespace
}  // namespace cradle

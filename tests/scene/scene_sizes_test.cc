// MuJoCo sizes of the BabyBench scenes: nconmax, njmax and nstack leave a
// margin over what random actions from random starts use, and an env stays far below 50 MB.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "core/config.h"
#include "core/rng.h"
#include "envs/babybench.h"
#include "scene/compose.h"

namespace cradle {
namespace {

struct Use {
  int contacts = 0, constraints = 0, stack = 0, overflows = 0, divergences = 0;
};

// High-water marks over `steps` random-action env steps, vision off, from random starts or not.
Use high_water(const char* file, int steps, bool random_starts) {
  Config config = load_config(std::string(CRADLE_SOURCE_DIR) + "/configs/" + file);
  config.vision_active = false;
  envs::BabyBenchEnv env(envs::make_assets(config), 0);
  env.set_randomize_start(random_starts);
  std::vector<double> action(env.action_space().size());
  Rng rng(7);
  Use use;
  env.reset(0);
  for (int t = 0; t < steps; ++t) {
    const Box& space = env.action_space();
    for (size_t k = 0; k < action.size(); ++k) action[k] = rng.uniform(space.low[k], space.high[k]);
    const envs::StepResult r = env.step(action);
    const mjData* d = env.data();
    use.contacts = std::max(use.contacts, d->maxuse_con);
    use.constraints = std::max(use.constraints, d->maxuse_efc);
    use.stack = std::max(use.stack, d->maxuse_stack);
    use.overflows += static_cast<int>(env.info().number(env.info().find("physics_overflow")) > 0);
    use.divergences += static_cast<int>(env.info().number(env.info().find("physics_diverged")) > 0);
    if (r.terminated || r.truncated || t % 200 == 199) env.reset();
  }
  return use;
}

void expect_margin(const char* file, SceneKind kind, int steps, bool random_starts = true) {
  const Use use = high_water(file, steps, random_starts);
  const scene::SceneSizes sizes = scene::scene_sizes(kind);
  std::printf(
      "%s: max %d contacts (nconmax %d), %d constraint rows (njmax %d), stack %d (nstack %d)\n",
      file, use.contacts, sizes.nconmax, use.constraints, sizes.njmax, use.stack, sizes.nstack);
  EXPECT_EQ(use.overflows, 0);
  EXPECT_EQ(use.divergences, 0);
  EXPECT_LE(1.5 * use.contacts, sizes.nconmax);
  EXPECT_LE(1.5 * use.constraints, sizes.njmax);
  EXPECT_LE(2 * use.stack, sizes.nstack);
}

TEST(SceneSizes, CribLeavesAMarginOverRandomPlay) {
  expect_margin("config_selftouch.yml", SceneKind::kCrib, 2000);
}

TEST(SceneSizes, CubesLeaveAMarginOverRandomPlay) {
  expect_margin("config_handregard.yml", SceneKind::kCubes, 2000);
}

// MIMo lies free on the floor here: random starts once put limbs through the floor and the
// physics diverged (NaN accelerations, hundreds of contacts); they now lift him out of it.
TEST(SceneSizes, BaseLeavesAMarginOverRandomPlay) {
  expect_margin("config_test_installation.yml", SceneKind::kBase, 2000);
}

}  // namespace
}  // namespace cradle

// The registration table (sami/envs/registry.h): every env's definition is whole and consistent
// with its robot, every robot has its model, and every env runs a few steps on every split. A new
// env gets these checks from its registration line; its own test checks what its hidden
// parameter does.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "sami/env.h"
#include "sami/envs/env_def.h"
#include "sami/models.h"
#include "sami/task.h"

namespace cradle::sami {
namespace {

TEST(SamiRegistry, EveryEnvIsDefinedWholeAndFindsItselfByName) {
  std::set<std::string> names;
  ASSERT_EQ(static_cast<int>(all_envs().size()), kEnvCount);
  for (EnvId id : all_envs()) {
    const EnvDef& def = env_def(id);
    const std::string name(env_name(id));
    SCOPED_TRACE(name);
    EXPECT_FALSE(name.empty());
    EXPECT_TRUE(names.insert(name).second) << "two envs named " << name;
    EXPECT_EQ(env_from_name(name), id);
    ASSERT_NE(def.split_sets, nullptr);
    // The spec: its keys tile the observation.
    const Spec spec = env_spec(id);
    EXPECT_EQ(spec.id, id);
    EXPECT_GT(spec.obs_size, 0);
    EXPECT_GT(spec.action_size, 0);
    EXPECT_GT(spec.horizon, 0);
    EXPECT_GT(spec.frame_skip, 0);
    EXPECT_GT(spec.dt, 0);
    int offset = 0;
    for (const ObsKey& key : spec.keys) {
      EXPECT_EQ(key.offset, offset) << key.name;
      offset += key.size;
    }
    EXPECT_EQ(offset, spec.obs_size);
    // A locomotion env: its rules are complete, it cripples exactly when its sets may, and its
    // robot has one actuator per action entry.
    if (def.make) continue;
    const LocomotionDef& loco = def.locomotion;
    EXPECT_NE(loco.reward, nullptr);
    EXPECT_NE(loco.observe, nullptr);
    EXPECT_NE(loco.scale, nullptr);
    EXPECT_EQ(loco.cripple != nullptr, def.varies.cripple_units > 0);
    EXPECT_LE(def.varies.max_crippled, 3);  // the most units an episode's draw holds
    const ModelPtr model = compile_robot(def.robot);
    EXPECT_EQ(model->nu, spec.action_size);
    EXPECT_NEAR(spec.frame_skip * model->opt.timestep, spec.dt, 1e-12);
  }
}

TEST(SamiRegistry, EveryRobotHasItsModelText) {
#define CRADLE_SAMI_ROBOT_CHECK(robot) EXPECT_FALSE(robot_xml(Robot::robot).empty()) << #robot;
  CRADLE_SAMI_ROBOTS(CRADLE_SAMI_ROBOT_CHECK)
#undef CRADLE_SAMI_ROBOT_CHECK
}

TEST(SamiRegistry, EveryEnvRunsOnEverySplitWithValidSets) {
  for (EnvId id : all_envs()) {
    SCOPED_TRACE(std::string(env_name(id)));
    const ModelPtr model = compile_robot(env_spec(id).robot);
    for (Split split : {Split::kTrain, Split::kModerate, Split::kExtreme}) {
      const std::vector<TaskSet> sets = split_sets(id, split);
      EXPECT_NO_THROW(validate(id, sets)) << split_name(split);
      auto env = make_env(id, sets, 3, model);
      env->reset(5);
      const std::vector<double> action(env->spec().action_size, 0.5 * env->spec().action_high);
      for (int t = 0; t < 5; ++t) {
        const StepResult out = env->step(action);
        EXPECT_TRUE(std::isfinite(out.reward));
      }
      for (float v : env->observation()) ASSERT_TRUE(std::isfinite(v)) << split_name(split);
      EXPECT_EQ(env->info().steps, 5);
    }
  }
}

}  // namespace
}  // namespace cradle::sami

// Composed scenes: every behaviour x scene x actuation compiles; each reference config survives
// 1,000 steps of zero control with its pose held; scene.xml round-trips through the disk.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/config.h"
#include "fixture.h"
#include "scene/compose.h"
#include "scene/summary.h"

namespace cradle::scene {
namespace {

namespace fs = std::filesystem;

using test::reference_config;

fs::path fresh_dir(const std::string& tag) { return test::fresh_dir("scene_test_" + tag); }

TEST(Scene, EveryBehaviourSceneAndActuationCompiles) {
  for (Behavior behavior : {Behavior::kNone, Behavior::kSelfTouch, Behavior::kHandRegard}) {
    for (SceneKind kind : {SceneKind::kBase, SceneKind::kCrib, SceneKind::kCubes}) {
      for (ActuationModel act :
           {ActuationModel::kSpringDamper, ActuationModel::kMuscle, ActuationModel::kPositional}) {
        Config c;
        c.behavior = behavior;
        c.scene = kind;
        c.actuation_model = act;
        const ModelPtr m = compile_scene(compose_scene(c));
        ASSERT_NE(m, nullptr);
        const ModelSummary s = summarize(m.get());
        const bool v2 = behavior == Behavior::kHandRegard;
        EXPECT_EQ(s.n_joints, v2 ? 91 : 47);
        EXPECT_EQ(s.n_actuators, v2 ? 88 : 44);
        EXPECT_EQ(m->ncam, 7);
        // Generated textures stay far below the reference's 1.46 GB per model.
        EXPECT_LE(m->ntexdata, 16 * 1024 * 1024);
      }
    }
  }
}

// Sizes of the reference example configs (babybench_layer.md §2.7 and §6).
TEST(Scene, ReferenceConfigSizes) {
  const ModelPtr hand = compile_scene(compose_scene(reference_config("config_handregard.yml")));
  EXPECT_EQ(hand->nu, 17);
  EXPECT_EQ(hand->njnt, 108);
  EXPECT_EQ(hand->nbody, 72);
  EXPECT_EQ(hand->ngeom, 93);
  EXPECT_EQ(hand->neq, 108);
  EXPECT_EQ(hand->nsensordata, 165);
  const ModelPtr touch = compile_scene(compose_scene(reference_config("config_selftouch.yml")));
  EXPECT_EQ(touch->nu, 30);
  EXPECT_EQ(touch->nsensordata, 69);
  const ModelPtr install =
      compile_scene(compose_scene(reference_config("config_test_installation.yml")));
  EXPECT_EQ(install->nu, 44);
}

// Locks requested by config are active from the compiled model on; joints the cubes scene already
// pins are left to the scene's own constraint.
TEST(Scene, ConfigLocksActiveAtLoad) {
  const ModelPtr m = compile_scene(compose_scene(reference_config("config_selftouch.yml")));
  int robot_locks = 0;
  for (int i = 0; i < m->neq; ++i) {
    const char* name = mj_id2name(m.get(), mjOBJ_EQUALITY, i);
    if (name && std::string(name).starts_with("robot:") && m->eq_active[i]) ++robot_locks;
  }
  EXPECT_EQ(robot_locks, 14);  // feet 8 + eyes 6

  const ModelPtr hr = compile_scene(compose_scene(reference_config("config_handregard.yml")));
  robot_locks = 0;
  for (int i = 0; i < hr->neq; ++i) {
    const char* name = mj_id2name(hr.get(), mjOBJ_EQUALITY, i);
    if (name && std::string(name).starts_with("robot:") && hr->eq_active[i]) ++robot_locks;
  }
  EXPECT_EQ(robot_locks, 16);  // v2 feet 10 + eyes 6; body and legs are pinned by the scene
}

// Runs n zero-control steps; fails on NaN or any MuJoCo warning.
void run_zero_control(const mjModel* m, mjData* d, int n) {
  for (int i = 0; i < n; ++i) {
    mj_step(m, d);
    for (int j = 0; j < m->nq; ++j) ASSERT_TRUE(std::isfinite(d->qpos[j])) << "step " << i;
  }
  for (int w = 0; w < mjNWARNING; ++w) EXPECT_EQ(d->warning[w].number, 0) << "warning " << w;
}

// Every active single-joint equality holds its joint within 1e-3 rad of its target; returns how
// many were checked.
int check_joint_locks(const mjModel* m, const mjData* d) {
  int checked = 0;
  for (int i = 0; i < m->neq; ++i) {
    if (m->eq_type[i] != mjEQ_JOINT || !m->eq_active[i]) continue;
    const int j = m->eq_obj1id[i];
    const double target = m->qpos0[m->jnt_qposadr[j]] + m->eq_data[mjNEQDATA * i];
    EXPECT_NEAR(d->qpos[m->jnt_qposadr[j]], target, 1e-3) << mj_id2name(m, mjOBJ_JOINT, j);
    ++checked;
  }
  return checked;
}

TEST(Scene, CribHoldsMimoOnTheMattress) {
  const ModelPtr m = compile_scene(compose_scene(reference_config("config_selftouch.yml")));
  mjData* d = mj_makeData(m.get());
  mj_forward(m.get(), d);
  const int lower = mj_name2id(m.get(), mjOBJ_BODY, "lower_body");
  const std::array<double, 3> start = {d->xpos[3 * lower], d->xpos[3 * lower + 1],
                                       d->xpos[3 * lower + 2]};
  run_zero_control(m.get(), d, 1000);
  // lower_body stays welded within 1 mm; every MIMo body stays inside the crib, above the mattress.
  double drift = 0;
  for (int k = 0; k < 3; ++k) drift += std::pow(d->xpos[3 * lower + k] - start[k], 2);
  EXPECT_LT(std::sqrt(drift), 1e-3);
  for (int b : subtree_bodies(m.get(), "hip")) {
    EXPECT_GT(d->xpos[3 * b], -0.57) << mj_id2name(m.get(), mjOBJ_BODY, b);
    EXPECT_LT(d->xpos[3 * b], 0.47);
    EXPECT_LT(std::abs(d->xpos[3 * b + 1]), 0.40);
    EXPECT_GT(d->xpos[3 * b + 2], 0.25);
  }
  EXPECT_EQ(check_joint_locks(m.get(), d), 14);  // feet and eyes locked by the config
  mj_deleteData(d);
}

TEST(Scene, CubesSittingPoseHolds) {
  const ModelPtr m = compile_scene(compose_scene(reference_config("config_handregard.yml")));
  mjData* d = mj_makeData(m.get());
  run_zero_control(m.get(), d, 1000);
  EXPECT_EQ(check_joint_locks(m.get(), d), 16 + 16);  // scene pose + config locks (feet, eyes)
  mj_deleteData(d);
}

TEST(Scene, BaseMimoFallsAndRestsOnTheFloor) {
  const ModelPtr m = compile_scene(compose_scene(reference_config("config_test_installation.yml")));
  mjData* d = mj_makeData(m.get());
  run_zero_control(m.get(), d, 1000);
  // Lying supine on the z = 0 plane: the hip is about one capsule radius above the floor.
  const int hip = mj_name2id(m.get(), mjOBJ_BODY, "hip");
  EXPECT_GT(d->xpos[3 * hip + 2], 0.02);
  EXPECT_LT(d->xpos[3 * hip + 2], 0.12);
  EXPECT_LT(std::abs(d->qvel[2]), 0.05);  // settled
  mj_deleteData(d);
}

// scene.xml written to disk compiles to the same model, from any working directory.
TEST(Scene, WrittenSceneRoundTrips) {
  for (const char* name : {"config_selftouch.yml", "config_handregard.yml"}) {
    const Config config = reference_config(name);
    const SceneFiles files = compose_scene(config);
    const ModelPtr a = compile_scene(files);
    const fs::path dir = fresh_dir(name);
    write_scene(files, dir);
    ASSERT_TRUE(fs::exists(dir / kSceneFileName));

    // Load by relative path from the parent folder to prove nothing depends on the cwd.
    const fs::path cwd = fs::current_path();
    fs::current_path(dir.parent_path());
    const ModelPtr b = load_scene(dir.filename() / kSceneFileName);
    fs::current_path(cwd);
    EXPECT_EQ(a->nq, b->nq);
    EXPECT_EQ(a->nv, b->nv);
    EXPECT_EQ(a->nu, b->nu);
    EXPECT_EQ(a->nbody, b->nbody);
    EXPECT_EQ(a->ngeom, b->ngeom);
    EXPECT_EQ(a->neq, b->neq);
    EXPECT_EQ(a->ntex, b->ntex);
    EXPECT_EQ(a->ntexdata, b->ntexdata);
    EXPECT_EQ(a->nsensordata, b->nsensordata);
    for (int i = 0; i < a->nbody; ++i) EXPECT_DOUBLE_EQ(a->body_mass[i], b->body_mass[i]);

    // The file starts with the config as a comment, and names no absolute path.
    std::ifstream in(dir / kSceneFileName);
    const std::string text((std::istreambuf_iterator<char>(in)), {});
    EXPECT_EQ(text.rfind("<!--", 0), 0u);
    EXPECT_NE(text.find("behavior: " + std::string(behavior_name(config.behavior))),
              std::string::npos);
    EXPECT_EQ(text.find("file=\"/"), std::string::npos);
    fs::remove_all(dir);
  }
}

// MuJoCo's own sample tools load the written scene from another directory (they exit 0 even on
// errors, so their output is what is judged).
TEST(Scene, MujocoSampleToolsLoadWrittenScene) {
  if (!fs::exists("/usr/bin/mujoco-compile")) GTEST_SKIP() << "libmujoco-samples not installed";
  const fs::path dir = fresh_dir("tools");
  write_scene(compose_scene(reference_config("config_selftouch.yml")), dir);
  const std::string cmd = "cd / && mujoco-compile " + (dir / kSceneFileName).string() + " " +
                          (dir / "scene.mjb").string() + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string output;
  char buf[256];
  while (fgets(buf, sizeof(buf), pipe)) output += buf;
  pclose(pipe);
  EXPECT_EQ(output.find("rror"), std::string::npos) << output;
  EXPECT_TRUE(fs::exists(dir / "scene.mjb")) << output;
  EXPECT_GT(fs::file_size(dir / "scene.mjb"), 1000u);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace cradle::scene

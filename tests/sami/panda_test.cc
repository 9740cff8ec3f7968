// Panda push: IK accuracy, fingers, reward and success, skill labels, task cells and splits.
#include "sami/panda.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <vector>

#include "sami/env.h"

namespace cradle::sami {
namespace {

struct Panda {
  std::unique_ptr<SamiEnv> env;
  int site, cube_qpos;

  explicit Panda(std::array<double, 2> cell = {0.1, 1.0})
      : env(make_env(EnvId::kPandaPush, {{.cells = {cell}}}, 0)) {
    const mjModel* m = env->model();
    site = mj_name2id(m, mjOBJ_SITE, "grasptarget");
    cube_qpos = m->jnt_qposadr[mj_name2id(m, mjOBJ_JOINT, "object")];
  }
  // The current end-effector position (kinematics refreshed; the state is not changed).
  std::array<double, 3> ee() {
    mj_forward(env->model(), env->data());
    const mjtNum* p = env->data()->site_xpos + 3 * site;
    return {p[0], p[1], p[2]};
  }
  void place_cube(double x, double y, double z) {
    mjtNum* q = env->data()->qpos + cube_qpos;
    q[0] = x, q[1] = y, q[2] = z;
    mj_forward(env->model(), env->data());
  }
  StepResult step(double dx, double dy, double dz, double fingers) {
    const double a[4] = {dx, dy, dz, fingers};
    return env->step(a);
  }
  double width() const {
    const auto obs = env->observation();
    return obs[6];
  }
};

TEST(SamiPanda, IkPutsTheEndEffectorAtTheCommandedDisplacement) {
  Panda p;
  p.env->reset(1);
  PandaIk ik(p.env->model());
  const std::array<std::array<double, 3>, 4> moves = {
      {{0, 0, -1}, {1, 0, 0}, {0, -1, 0}, {0.5, 0.5, 0.5}}};
  for (const auto& a : moves) {
    const auto start = p.ee();
    const mjtNum target[3] = {start[0] + 0.05 * a[0], start[1] + 0.05 * a[1],
                              start[2] + 0.05 * a[2]};
    mjtNum q[7];
    ik.solve(p.env->model(), p.env->data()->qpos, target, q);
    const mjtNum* reached = ik.scratch()->site_xpos + 3 * ik.site();
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(reached[i], target[i], 0.005) << i;
    EXPECT_NEAR(ik.scratch()->site_xmat[9 * ik.site() + 8], -1.0, 1e-3);  // still pointing down
  }
}

TEST(SamiPanda, EndEffectorFollowsTheCommandInFreeSpace) {
  // The motors lag the IK targets (PyBullet's 50/s velocity servo, force-limited, starting from
  // rest), so a command held for 3 steps (15 cm) covers at least 6 cm in its direction, with
  // little motion sideways.
  for (const auto& a : std::array<std::array<double, 3>, 3>{{{0, 0, -1}, {0, 1, 0}, {-1, 0, 0}}}) {
    Panda p;
    p.env->reset(1);
    p.place_cube(0.15, -0.15, 0.02);  // out of the way
    const auto before = p.ee();
    for (int t = 0; t < 3; ++t) p.step(a[0], a[1], a[2], 0);
    const auto after = p.ee();
    for (int i = 0; i < 3; ++i) {
      if (a[i] != 0) {
        EXPECT_GT((after[i] - before[i]) * a[i], 0.06) << i;
      } else {
        EXPECT_NEAR(after[i], before[i], 0.015) << i;
      }
    }
  }
}

TEST(SamiPanda, FingersCloseOnTheCubeAndALiftIsPickAndPlace) {
  Panda p;
  p.env->reset(2);
  const auto ee = p.ee();
  p.place_cube(ee[0], ee[1], 0.02);
  // Open, go down around the cube, close.
  for (int t = 0; t < 5; ++t) p.step(0, 0, -1, 1);
  EXPECT_GT(p.width(), 0.07);
  for (int t = 0; t < 5; ++t) p.step(0, 0, 0, -1);
  EXPECT_NEAR(p.width(), 0.04, 0.003);
  // Lift.
  for (int t = 0; t < 4; ++t) p.step(0, 0, 1, -1);
  const double z = p.env->data()->qpos[p.cube_qpos + 2];
  EXPECT_GT(z, 0.08);
  EXPECT_EQ(p.env->info().skill, Skill::kPickAndPlace);
  EXPECT_EQ(p.env->info().episode_skill, Skill::kPickAndPlace);
}

TEST(SamiPanda, APushedCubeIsLabelledPush) {
  Panda p;
  p.env->reset(3);
  const auto ee = p.ee();
  p.place_cube(ee[0] + 0.08, ee[1], 0.02);
  for (int t = 0; t < 6; ++t) p.step(0, 0, -1, 0);
  const double x0 = p.env->data()->qpos[p.cube_qpos];
  for (int t = 0; t < 6; ++t) p.step(1, 0, 0, 0);
  EXPECT_GT(p.env->data()->qpos[p.cube_qpos] - x0, 0.05);
  EXPECT_EQ(p.env->info().episode_skill, Skill::kPush);
}

TEST(SamiPanda, RewardIsMinusTheGoalDistanceAndSuccessTerminates) {
  Panda p;
  p.env->reset(4);
  const auto obs = p.env->observation();
  const std::array<double, 3> goal = {obs[22], obs[23], obs[24]};
  EXPECT_DOUBLE_EQ(goal[2], 0.02);
  // Cube far from the goal: reward -distance, no success.
  const double far_x = goal[0] > 0 ? goal[0] - 0.2 : goal[0] + 0.2;
  p.place_cube(far_x, goal[1], 0.02);
  StepResult r = p.step(0, 0, 0, 0);
  const auto o = p.env->observation();
  const double d = std::hypot(o[7] - goal[0], o[8] - goal[1], o[9] - goal[2]);
  EXPECT_NEAR(r.reward, -d, 1e-6);
  EXPECT_FALSE(r.terminated);
  EXPECT_FALSE(p.env->info().is_success);
  // Cube on the goal: success ends the episode.
  p.place_cube(goal[0] + 0.01, goal[1], 0.02);
  r = p.step(0, 0, 0, 0);
  EXPECT_TRUE(p.env->info().is_success);
  EXPECT_TRUE(r.terminated);
}

TEST(SamiPanda, EveryGridCellBelongsToExactlyOneSplit) {
  std::map<std::array<double, 2>, std::vector<Split>> member;
  for (Split s : {Split::kTrain, Split::kModerate, Split::kExtreme}) {
    for (const auto& cell : panda_cells(s)) member[cell].push_back(s);
  }
  for (double f : {0.1, 1.0, 5.0, 10.0, 30.0}) {
    for (double m : {1.0, 5.0, 10.0, 30.0}) {
      const std::vector<Split>& splits = member[std::array<double, 2>{f, m}];
      ASSERT_EQ(splits.size(), 1u) << f << " " << m;
      const Split s = splits[0];
      // Training: low friction with light cubes or friction <= 10 with the 1 kg cube.
      const bool train = (f == 0.1 && m <= 10) || (f <= 10 && m == 1);
      const bool extreme = m == 30 || f == 30;
      EXPECT_EQ(s, train     ? Split::kTrain
                   : extreme ? Split::kExtreme
                             : Split::kModerate)
          << f << " " << m;
    }
  }
  EXPECT_EQ(member.size(), 20u);
  // One sub-env per cell.
  EXPECT_EQ(split_sets(EnvId::kPandaPush, Split::kExtreme).size(), 8u);
}

TEST(SamiPanda, CellsSetTableFrictionAndCubeMassOnThePrivateModel) {
  Panda p({30.0, 5.0});
  p.env->reset(0);
  const mjModel* m = p.env->model();
  const int table = mj_name2id(m, mjOBJ_GEOM, "table");
  const int cube = mj_name2id(m, mjOBJ_BODY, "object");
  EXPECT_DOUBLE_EQ(m->geom_friction[3 * table], 10.0);  // 0.5 * 30 clipped at 10
  EXPECT_DOUBLE_EQ(m->body_mass[cube], 5.0);
  EXPECT_NEAR(m->body_inertia[3 * cube], 5 * 2.667e-4, 1e-12);
  EXPECT_DOUBLE_EQ(p.env->shared_model()->body_mass[cube], 1.0);
  EXPECT_EQ(p.env->info().friction, 30.0);
  EXPECT_EQ(p.env->info().mass, 5.0);
  // A resting cube stays on the table (z within 1 mm of 0.02) and is not "down".
  for (int t = 0; t < 5; ++t) p.step(0, 0, 0, 0);
  EXPECT_NEAR(p.env->data()->qpos[p.cube_qpos + 2], 0.02, 1e-3);
  EXPECT_EQ(panda_skill(m, p.env->data()), Skill::kPush);
}

TEST(SamiPanda, SeededEpisodesAreDeterministic) {
  auto run = [] {
    auto env = make_env(EnvId::kPandaPush, split_sets(EnvId::kPandaPush, Split::kTrain), 9);
    env->reset(5);
    std::vector<double> trace(env->observation().begin(), env->observation().end());
    for (int t = 0; t < 10; ++t) {
      const double a[4] = {std::sin(t), std::cos(t), -0.5, 0.2};
      trace.push_back(env->step(a).reward);
    }
    return trace;
  };
  EXPECT_EQ(run(), run());
}

}  // namespace
}  // namespace cradle::sami

// Panda push: IK accuracy, fingers, reward and success, skill labels, task cells and splits.
#include "sami/panda.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <utility>
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
  EXPECT_EQ(goal[2], 0.02f);  // float32, as the reference's
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
  EXPECT_DOUBLE_EQ(m->geom_friction[3 * table], 30.0);  // Bullet's coefficient of the table
  EXPECT_DOUBLE_EQ(p.env->shared_model()->geom_friction[3 * table], 1.0);
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

// PyBullet's lateral coefficient of each Panda geom: the table's is the task's, the cube keeps the
// default 0.5, panda-gym sets the fingers to 1.0, every other body has the default 0.5.
double bullet_coefficient(const std::string& geom, double table) {
  if (geom == "table") return table;
  if (geom == "leftfinger" || geom == "rightfinger") return 1.0;
  return 0.5;
}

std::string geom_name(const mjModel* m, int g) {
  const char* name = mj_id2name(m, mjOBJ_GEOM, g);
  return name ? name : "";
}

// The contacts of the current state as {geom, geom} (sorted names) -> lateral friction.
std::map<std::pair<std::string, std::string>, std::array<double, 2>> contact_friction(
    const mjModel* m, const mjData* d) {
  std::map<std::pair<std::string, std::string>, std::array<double, 2>> out;
  for (int i = 0; i < d->ncon; ++i) {
    std::string a = geom_name(m, d->contact[i].geom1), b = geom_name(m, d->contact[i].geom2);
    if (b < a) std::swap(a, b);
    out[{a, b}] = {d->contact[i].friction[0], d->contact[i].friction[1]};
  }
  return out;
}

// Bullet multiplies the two bodies' frictions (clipped at 10), MuJoCo would take the larger: with
// the fingers pressed on the table, the cube on it and the hand in the cube, every contact's
// friction in mjData is the product, for every table friction of the task grid.
TEST(SamiPanda, ContactFrictionIsBulletsProductForEveryPair) {
  for (const double f : {0.1, 1.0, 5.0, 10.0, 30.0}) {
    SCOPED_TRACE(f);
    Panda p({f, 1.0});
    p.env->reset(0);
    const mjModel* m = p.env->model();
    mjData* d = p.env->data();
    const auto check = [&](const std::set<std::pair<std::string, std::string>>& expected) {
      const auto contacts = contact_friction(m, d);
      for (const auto& pair : expected)
        EXPECT_TRUE(contacts.count(pair)) << pair.first << "-" << pair.second;
      for (const auto& [pair, mu] : contacts) {
        const double want =
            std::min(bullet_coefficient(pair.first, f) * bullet_coefficient(pair.second, f), 10.0);
        EXPECT_DOUBLE_EQ(mu[0], want) << pair.first << "-" << pair.second;
        EXPECT_DOUBLE_EQ(mu[1], want) << pair.first << "-" << pair.second;
      }
    };
    // Fingers 2 mm into the table, away from the cube.
    PandaIk ik(m);
    const mjtNum target[3] = {0, 0, 0.0034 - 0.002};  // fingertips are 3.4 mm below the target
    mjtNum q[7];
    ik.solve(m, d->qpos, target, q);
    for (int k = 0; k < 7; ++k) d->qpos[ik.arm_qpos(k)] = q[k];
    p.place_cube(0.1, 0.1, 0.0199);
    check({{"leftfinger", "table"}, {"rightfinger", "table"}, {"object", "table"}});
    // The cube inside the hand (above the fingers) and, separately, on a finger.
    const int hand = mj_name2id(m, mjOBJ_GEOM, "hand");
    const mjtNum* h = d->geom_xpos + 3 * hand;
    p.place_cube(h[0], h[1], h[2]);
    check({{"hand", "object"}});
    const int finger = mj_name2id(m, mjOBJ_GEOM, "leftfinger");
    // Outside the finger along its opening axis (the finger's local y), 2 mm into it.
    const mjtNum* g = d->geom_xpos + 3 * finger;
    const mjtNum* r = d->geom_xmat + 9 * finger;
    p.place_cube(g[0] + 0.026 * r[1], g[1] + 0.026 * r[4], g[2] + 0.026 * r[7]);
    check({{"leftfinger", "object"}});
  }
}

// The arm's links and the hand collide with the table (only the fingers did): with the fingers
// moved into the hand, a 200 N push drives the hand down onto the table, and it stays on top.
TEST(SamiPanda, TheHandCannotPassThroughTheTable) {
  const ModelPtr shared = compile_robot(Robot::kPanda);
  mjModel* m = mj_copyModel(nullptr, shared.get());
  for (const char* name : {"leftfinger", "rightfinger"}) {
    const int g = mj_name2id(m, mjOBJ_GEOM, name);
    m->geom_pos[3 * g + 2] = -0.03;  // inside the hand box
    for (int i = 0; i < 3; ++i) m->geom_size[3 * g + i] = 1e-3;
  }
  mjData* d = mj_makeData(m);
  PandaIk ik(m);
  const mjtNum target[3] = {0.05, 0, 0.1};
  mjtNum q[7];
  ik.solve(m, d->qpos, target, q);
  for (int k = 0; k < 7; ++k) d->qpos[ik.arm_qpos(k)] = q[k];
  // The cube out of the way, in the table's far corner.
  const int cube_qpos = m->jnt_qposadr[mj_name2id(m, mjOBJ_JOINT, "object")];
  d->qpos[cube_qpos] = 0.2, d->qpos[cube_qpos + 1] = 0.3;
  const int hand_body = mj_name2id(m, mjOBJ_BODY, "hand");
  const int hand = mj_name2id(m, mjOBJ_GEOM, "hand");
  const int table = mj_name2id(m, mjOBJ_GEOM, "table");
  // The lowest point of the hand box.
  const auto bottom = [&] {
    const mjtNum* r = d->geom_xmat + 9 * hand;
    const mjtNum* half = m->geom_size + 3 * hand;
    double z = d->geom_xpos[3 * hand + 2];
    for (int k = 0; k < 3; ++k) z -= std::abs(r[6 + k]) * half[k];
    return z;
  };
  mj_forward(m, d);
  EXPECT_GT(bottom(), 0.1);
  double lowest = 1;
  bool touched = false;
  for (int t = 0; t < 1000; ++t) {
    d->xfrc_applied[6 * hand_body + 2] = -200;
    mj_step(m, d);
    lowest = std::min(lowest, bottom());
    for (int i = 0; i < d->ncon; ++i) {
      const mjContact& c = d->contact[i];
      touched |= (c.geom1 == hand && c.geom2 == table) || (c.geom1 == table && c.geom2 == hand);
    }
  }
  EXPECT_TRUE(touched);
  EXPECT_GT(lowest, -0.005);  // a few millimetres of soft-contact penetration at most
  EXPECT_LT(bottom(), 0.01);  // it did come down to the table
  mj_deleteData(d);
  mj_deleteModel(m);
}

}  // namespace
}  // namespace cradle::sami

// Compiled numbers of the generated SaMI models against shared/spec/sami_models.md.
#include "sami/models.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <vector>

namespace cradle::sami {
namespace {

struct Sizes {
  int nq, nv, nu, nbody, njnt, ngeom;
  double total_mass;
  int integrator;
  double timestep;
  int solver, iterations;
};

void expect_sizes(const mjModel* m, const Sizes& s) {
  EXPECT_EQ(m->nq, s.nq);
  EXPECT_EQ(m->nv, s.nv);
  EXPECT_EQ(m->nu, s.nu);
  EXPECT_EQ(m->nbody, s.nbody);
  EXPECT_EQ(m->njnt, s.njnt);
  EXPECT_EQ(m->ngeom, s.ngeom);
  double mass = 0;
  for (int b = 0; b < m->nbody; ++b) mass += m->body_mass[b];
  EXPECT_NEAR(mass, s.total_mass, 1e-5);
  EXPECT_EQ(m->opt.integrator, s.integrator);
  EXPECT_DOUBLE_EQ(m->opt.timestep, s.timestep);
  EXPECT_EQ(m->opt.solver, s.solver);
  EXPECT_EQ(m->opt.iterations, s.iterations);
  EXPECT_DOUBLE_EQ(m->opt.gravity[2], -9.81);
  EXPECT_EQ(m->nsensor, 0);
  EXPECT_EQ(m->neq, 0);
}

void expect_masses(const mjModel* m, const std::vector<double>& masses) {
  ASSERT_EQ(static_cast<int>(masses.size()), m->nbody - 1);
  for (int b = 1; b < m->nbody; ++b) EXPECT_NEAR(m->body_mass[b], masses[b - 1], 2e-6) << b;
}

void expect_damping(const mjModel* m, const std::vector<double>& damping) {
  ASSERT_EQ(static_cast<int>(damping.size()), m->nv);
  for (int v = 0; v < m->nv; ++v) EXPECT_NEAR(m->dof_damping[v], damping[v], 1e-12) << v;
}

void expect_gears(const mjModel* m, const std::vector<double>& gears) {
  ASSERT_EQ(static_cast<int>(gears.size()), m->nu);
  for (int u = 0; u < m->nu; ++u) {
    EXPECT_DOUBLE_EQ(m->actuator_gear[6 * u], gears[u]) << u;
    EXPECT_TRUE(m->actuator_ctrllimited[u]);
  }
}

TEST(SamiModels, HalfCheetahMatchesSpec) {
  ModelPtr m = compile_robot(Robot::kHalfCheetah);
  expect_sizes(m.get(), {9, 9, 6, 8, 9, 9, 14.0, mjINT_EULER, 0.01, mjSOL_NEWTON, 100});
  expect_masses(m.get(), {6.250209, 1.543515, 1.587448, 1.095397, 1.438075, 1.200837, 0.884519});
  expect_damping(m.get(), {0, 0, 0, 6, 4.5, 3, 4.5, 3, 1.5});
  expect_gears(m.get(), {120, 90, 60, 120, 60, 30});
  const double stiffness[6] = {240, 180, 120, 180, 120, 60};
  for (int j = 0; j < 6; ++j) EXPECT_DOUBLE_EQ(m->jnt_stiffness[3 + j], stiffness[j]);
  for (int v = 3; v < 9; ++v) EXPECT_DOUBLE_EQ(m->dof_armature[v], 0.1);
  for (int q = 0; q < 9; ++q) EXPECT_EQ(m->qpos0[q], 0);
}

TEST(SamiModels, AntMatchesSpec) {
  ModelPtr m = compile_robot(Robot::kAnt);
  expect_sizes(m.get(), {15, 14, 8, 14, 9, 14, 0.910880, mjINT_RK4, 0.01, mjSOL_NEWTON, 100});
  std::vector<double> masses = {0.327249};
  for (int k = 0; k < 4; ++k) masses.insert(masses.end(), {0.039158, 0.039158, 0.067592});
  expect_masses(m.get(), masses);
  std::vector<double> damping(6, 0.0);
  damping.resize(14, 1.0);
  expect_damping(m.get(), damping);
  expect_gears(m.get(), std::vector<double>(8, 150));
  // Actuator order: hip_4, ankle_4, hip_1, ankle_1, ... (dofs 12, 13, 6, 7, 8, 9, 10, 11).
  const int dofs[8] = {12, 13, 6, 7, 8, 9, 10, 11};
  for (int u = 0; u < 8; ++u) EXPECT_EQ(m->jnt_dofadr[m->actuator_trnid[2 * u]], dofs[u]);
  EXPECT_NEAR(m->body_inertia[3], 8.18123e-3, 1e-8);
  EXPECT_NEAR(m->body_inertia[3 * 4], 2.67479e-3, 1e-8);
  // Ankle 1 range [30, 70] degrees.
  EXPECT_NEAR(m->jnt_range[2 * 2], 30 * M_PI / 180, 1e-9);
  EXPECT_NEAR(m->qpos0[2], 0.75, 1e-12);
  EXPECT_EQ(m->qpos0[3], 1);
}

TEST(SamiModels, HopperMatchesSpec) {
  ModelPtr m = compile_robot(Robot::kHopper);
  expect_sizes(m.get(), {6, 6, 3, 5, 6, 5, 15.820013, mjINT_RK4, 0.002, mjSOL_NEWTON, 100});
  expect_masses(m.get(), {3.665191, 4.057891, 2.781357, 5.315575});
  expect_damping(m.get(), {0, 0, 0, 1, 1, 1});
  expect_gears(m.get(), {200, 200, 200});
  EXPECT_DOUBLE_EQ(m->qpos0[1], 1.25);
  // Foot friction 2.0, floor contacts condim 3, body geoms condim 1.
  EXPECT_DOUBLE_EQ(m->geom_friction[3 * 4], 2.0);
  EXPECT_EQ(m->geom_condim[0], 3);
  EXPECT_EQ(m->geom_condim[1], 1);
}

TEST(SamiModels, WalkerMatchesSpec) {
  ModelPtr m = compile_robot(Robot::kWalker);
  expect_sizes(m.get(), {9, 9, 6, 8, 9, 8, 23.677137, mjINT_RK4, 0.002, mjSOL_NEWTON, 100});
  expect_masses(m.get(), {3.665191, 4.057891, 2.781357, 3.166725, 4.057891, 2.781357, 3.166725});
  expect_damping(m.get(), {0, 0, 0, 0.1, 0.1, 0.1, 0.1, 0.1, 0.1});
  expect_gears(m.get(), std::vector<double>(6, 100));
  EXPECT_DOUBLE_EQ(m->geom_friction[3 * 4], 0.9);
  EXPECT_DOUBLE_EQ(m->geom_friction[3 * 7], 1.9);
}

TEST(SamiModels, HumanoidMatchesSpec) {
  ModelPtr m = compile_robot(Robot::kHumanoid);
  expect_sizes(m.get(), {24, 23, 17, 14, 18, 18, 42.116030, mjINT_RK4, 0.003, mjSOL_PGS, 50});
  expect_masses(m.get(), {8.907462, 2.261947, 6.616194, 4.751751, 2.755696, 1.767146, 4.751751,
                          2.755696, 1.767146, 1.661080, 1.229540, 1.661080, 1.229540});
  expect_damping(m.get(), {0, 0, 0, 0, 0, 0, 5, 5, 5, 5, 5, 5, 1, 5, 5, 5, 1, 1, 1, 1, 1, 1, 1});
  expect_gears(m.get(),
               {100, 100, 100, 100, 100, 300, 200, 100, 100, 300, 200, 25, 25, 25, 25, 25, 25});
  EXPECT_DOUBLE_EQ(m->actuator_ctrlrange[1], 0.4);
  // Actuator 0 drives abdomen_y (dof 7) while dof 6 is abdomen_z.
  EXPECT_EQ(m->jnt_dofadr[m->actuator_trnid[0]], 7);
  // The lying model: 10 contacts at qpos0.
  mjData* d = mj_makeData(m.get());
  mj_forward(m.get(), d);
  EXPECT_EQ(d->ncon, 10);
  mj_deleteData(d);
}

TEST(SamiModels, PandaNeutralPoseMatchesForwardKinematics) {
  ModelPtr m = compile_robot(Robot::kPanda);
  EXPECT_EQ(m->nu, 9);
  mjData* d = mj_makeData(m.get());
  const double neutral[7] = {0, 0.41, 0, -1.85, 0, 2.26, 0.79};
  for (int k = 0; k < 7; ++k) {
    const int j = mj_name2id(m.get(), mjOBJ_JOINT, ("joint" + std::to_string(k + 1)).c_str());
    d->qpos[m->jnt_qposadr[j]] = neutral[k];
  }
  mj_forward(m.get(), d);
  const int site = mj_name2id(m.get(), mjOBJ_SITE, "grasptarget");
  EXPECT_NEAR(d->site_xpos[3 * site], 0.0384, 5e-4);
  EXPECT_NEAR(d->site_xpos[3 * site + 1], 0.0, 5e-4);
  EXPECT_NEAR(d->site_xpos[3 * site + 2], 0.1974, 5e-4);
  // Pointing down: site z axis along world -z, fingers opening along world y.
  EXPECT_NEAR(d->site_xmat[9 * site + 8], -1.0, 1e-3);
  EXPECT_NEAR(std::abs(d->site_xmat[9 * site + 4]), 1.0, 1e-3);
  mj_deleteData(d);
}

}  // namespace
}  // namespace cradle::sami

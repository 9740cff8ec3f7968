// MuJoCo size overflows: a step that runs out of contacts, constraint rows or
// stack is counted and ends early instead of silently dropping physics; the next step is normal
// once the cause is gone. A diverging step is counted and ends early the same way.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <string>
#include <vector>

#include "core/error.h"
#include "sim/mujoco_handlers.h"
#include "sim/sim.h"

namespace cradle::sim {
namespace {

// Six boxes dropped onto the floor (4 contacts each once they land, after ~90 steps).
std::string boxes(const std::string& size) {
  std::string xml = "<mujoco><size " + size + "/><worldbody><geom type=\"plane\" size=\"2 2 .1\"/>";
  for (int i = 0; i < 6; ++i) {
    xml += "<body pos=\"" + std::to_string(0.3 * i) +
           " 0 0.2\"><freejoint/>"
           "<geom type=\"box\" size=\"0.05 0.05 0.05\"/></body>";
  }
  return xml + "</worldbody></mujoco>";
}

struct ModelFree {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};

std::unique_ptr<mjModel, ModelFree> compile(const std::string& xml) {
  install_mujoco_handlers();
  char error[1000] = "";
  mjVFS vfs;
  mj_defaultVFS(&vfs);
  mj_makeEmptyFileVFS(&vfs, "m.xml", static_cast<int>(xml.size()));
  std::copy(xml.begin(), xml.end(), static_cast<char*>(vfs.filedata[0]));
  mjModel* m = mj_loadXML("m.xml", &vfs, error, sizeof error);
  mj_deleteVFS(&vfs);
  EXPECT_NE(m, nullptr) << error;
  return std::unique_ptr<mjModel, ModelFree>(m);
}

// Overflows counted over `steps` zero-action steps.
int overflows(const mjModel* m, int steps) {
  Sim sim(m, ActuationModel::kSpringDamper, 1);
  int n = 0;
  for (int t = 0; t < steps; ++t) {
    sim.step({});
    n += sim.overflows();
  }
  return n;
}

TEST(Overflow, RoomyModelNeverOverflows) {
  const auto m = compile(boxes("nconmax=\"100\" njmax=\"400\" nstack=\"200000\""));
  ASSERT_NE(m, nullptr);
  EXPECT_EQ(overflows(m.get(), 200), 0);
}

TEST(Overflow, ContactsBeyondNconmaxAreCounted) {
  const auto m = compile(boxes("nconmax=\"8\" njmax=\"400\" nstack=\"200000\""));
  ASSERT_NE(m, nullptr);
  ::testing::internal::CaptureStderr();
  EXPECT_GT(overflows(m.get(), 200), 80);  // 24 contacts in every step after landing
  ::testing::internal::GetCapturedStderr();
}

TEST(Overflow, ConstraintsBeyondNjmaxAreCounted) {
  const auto m = compile(boxes("nconmax=\"100\" njmax=\"30\" nstack=\"200000\""));
  ASSERT_NE(m, nullptr);
  ::testing::internal::CaptureStderr();
  EXPECT_GT(overflows(m.get(), 200), 80);  // 24 elliptic contacts need 72 rows
  ::testing::internal::GetCapturedStderr();
}

TEST(Overflow, StackOverflowIsCountedAndTheSimGoesOn) {
  const auto m = compile(boxes("nconmax=\"100\" njmax=\"400\" nstack=\"3000\""));
  ASSERT_NE(m, nullptr);
  Sim sim(m.get(), ActuationModel::kSpringDamper, 1);
  int n = 0;
  for (int t = 0; t < 200; ++t) {
    sim.step({});  // never a crash
    n += sim.overflows();
    EXPECT_EQ(sim.data()->pstack, 0);
  }
  EXPECT_GT(n, 80);
}

// A diverging substep (here a velocity beyond MuJoCo's 1e10 bound) makes MuJoCo reset the data
// mid-step; the step ends there and says so, and the next step is normal again.
TEST(Overflow, DivergenceEndsTheStepAndIsCounted) {
  const auto m = compile(boxes("nconmax=\"100\" njmax=\"400\" nstack=\"200000\""));
  ASSERT_NE(m, nullptr);
  Sim sim(m.get(), ActuationModel::kSpringDamper, 5);
  sim.step({});
  EXPECT_EQ(sim.divergences(), 0);
  sim.data()->qvel[0] = 1e11;
  ::testing::internal::CaptureStderr();
  sim.step({});
  const std::string warning = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(warning.find("QVEL"), std::string::npos) << warning;
  EXPECT_EQ(sim.divergences(), 1);
  EXPECT_EQ(sim.overflows(), 0);
  // Stopped at the diverging substep: MuJoCo's reset, then that one step (not five).
  EXPECT_NEAR(sim.data()->time, m->opt.timestep, 1e-12);
  EXPECT_NEAR(sim.data()->qpos[2], m->qpos0[2], 1e-3);  // box 0 back at its initial height
  sim.step({});
  EXPECT_EQ(sim.divergences(), 0);
  // A second divergence in the same life of the data is counted too.
  sim.data()->qvel[0] = 1e11;
  ::testing::internal::CaptureStderr();
  sim.step({});
  ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(sim.divergences(), 1);
}

}  // namespace
}  // namespace cradle::sim

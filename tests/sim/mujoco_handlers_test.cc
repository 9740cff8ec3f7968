// MuJoCo's fatal errors become one-line UserErrors at the failing call (no "Press Enter", no
// MUJOCO_LOG.TXT); warnings go to stderr, never stdout.
#include "sim/mujoco_handlers.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <filesystem>
#include <string>

#include "core/error.h"

namespace cradle::sim {
namespace {

TEST(MujocoHandlers, ErrorsAreUserErrorsAndWarningsGoToStderr) {
  install_mujoco_handlers();
  install_mujoco_handlers();  // idempotent
  try {
    mju_error("allocation failed\nsecond line");
    FAIL() << "mju_error returned";
  } catch (const UserError& e) {
    EXPECT_EQ(std::string(e.what()), "MuJoCo: allocation failed second line");
  }
  ::testing::internal::CaptureStdout();
  ::testing::internal::CaptureStderr();
  mju_warning("something odd");
  const std::string out = ::testing::internal::GetCapturedStdout();
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(out, "");
  EXPECT_EQ(err, "cradle: MuJoCo warning: something odd\n");
  EXPECT_FALSE(std::filesystem::exists("MUJOCO_LOG.TXT"));
}

}  // namespace
}  // namespace cradle::sim

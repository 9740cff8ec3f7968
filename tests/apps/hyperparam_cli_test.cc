// `--hp` through the binary for `sami train`, `tma run` and `train`: sizes the machine cannot hold,
// lists cut short or empty where a network needs a layer, and the same name twice are one-line
// errors with exit 1 (they were std::bad_alloc, LibTorch traces or a silently dropped value).
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "fixture.h"

namespace {

namespace fs = std::filesystem;

// Runs `cradle <args>` with no input and expects one error line holding `expected`, exit 1.
void expect_error(const std::string& args, const std::string& expected) {
  const cradle::test::RunResult r = cradle::test::run_cradle(args + " </dev/null");
  EXPECT_EQ(r.status, 1) << args << "\n" << r.out;
  const std::vector<std::string> lines = cradle::test::message_lines(r.out);
  ASSERT_EQ(lines.size(), 1u) << args << "\n" << r.out;
  EXPECT_EQ(lines[0].rfind("cradle: error: ", 0), 0u) << args << "\n" << r.out;
  EXPECT_NE(lines[0].find(expected), std::string::npos) << args << "\n" << r.out;
}

TEST(HyperparamCli, SamiTrainRefusesSizesBeyondMemoryAndRepeatedNames) {
  const fs::path dir = cradle::test::fresh_dir("hp_sami");
  const std::string train =
      "sami train --env PandaPush --method CCM --seed 1 --no-progress "
      "--steps-per-env 10 --out " +
      (dir / "run").string();
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--hp buffer_size=1000000000", "half the machine's memory"},
      {"--hp net_arch=100000000", "net_arch: expected every layer size in 1..65536"},
      {"--hp lstm_hidden=65536", "half the machine's memory"},
      {"--hp net_arch=65536,65536", "half the machine's memory"},
      {"--hp net_arch=", "net_arch: expected at least one layer"},
      {"--hp net_arch=64,", "cannot parse '64,'"},
      {"--hp batch_size=0", "batch_size"},
      {"--hp buffer_size=10 --hp buffer_size=20", "--hp buffer_size is given twice"}};
  for (const auto& [hp, expected] : cases) expect_error(train + " " + hp, expected);
  // Nothing was started: no checkpoint to resume from.
  EXPECT_FALSE(fs::exists(dir / "run" / "checkpoints" / "latest.ckpt"));
  fs::remove_all(dir);
}

TEST(HyperparamCli, TmaRunRefusesEmptyOrShortListsSizesBeyondMemoryAndRepeatedNames) {
  const fs::path dir = cradle::test::fresh_dir("hp_tma");
  const std::string run =
      "tma run --env stump-tracks --teacher Random --nb_env_steps 0.0005 "
      "--test_every 200 --nb_test_episodes 1 --no-progress --out " +
      (dir / "run").string();
  const std::string sac = run + " --student sac";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {sac + " --hp pi_layers=", "sac: pi_layers and qf_layers need at least one hidden layer"},
      {sac + " --hp qf_layers=", "got qf_layers empty"},
      {sac + " --hp pi_layers=0", "expected 1 <= pi_layers <= 65536"},
      {sac + " --hp pi_layers=abc", "cannot parse 'abc'"},
      {sac + " --hp pi_layers=64,", "cannot parse '64,'"},
      {sac + " --hp batch_size=0", "expected 1 <= batch_size"},
      {sac + " --hp pi_layers=65536,65536", "half the machine's memory"},
      {sac + " --hp qf_layers=65536,65536", "half the machine's memory"},
      {sac + " --hp buffer_size=1000000000", "half the machine's memory"},
      {sac + " --hp batch_size=10 --hp batch_size=20", "--hp batch_size is given twice"},
      {sac + " --lr 0.01 --hp learning_rate=0.1", "given twice (also by --lr)"},
      {run + " --student ppo --hp shared_layers=65536,65536,65536", "half the machine's memory"}};
  for (const auto& [args, expected] : cases) expect_error(args, expected);
  fs::remove_all(dir);
}

// Seeds of tma and sami runs are decimal integers from 0 to 2^64 - 1, as train's: -1 wrapped to
// 2^64 - 1, 2^64 saturated and 0x10 read as 16.
TEST(HyperparamCli, TmaAndSamiSeedsAreDecimalIn64Bits) {
  const fs::path dir = cradle::test::fresh_dir("hp_seeds");
  const std::string out = " --no-progress --out " + (dir / "run").string();
  for (const char* seed : {"-1", "18446744073709551616", "0x10", "1.5", "abc"}) {
    const std::string flag = std::string(" --seed ") + seed;
    expect_error("tma run --env stump-tracks --student sac --teacher Random --nb_env_steps 0.0002" +
                     out + flag,
                 "seed");
    expect_error("sami train --env PandaPush --method CCM --steps-per-env 5" + out + flag, "seed");
    expect_error("tma random --env stump-tracks" + flag, "seed");
  }
  EXPECT_FALSE(fs::exists(dir / "run"));
  fs::remove_all(dir);
}

TEST(HyperparamCli, TrainRefusesARepeatedName) {
  const fs::path dir = cradle::test::fresh_dir("hp_train");
  expect_error("train --config " + cradle::test::self_touch_config(dir, 100) +
                   " --eval-episodes 0 --hp gamma=0.9 --hp gamma=0.8",
               "--hp gamma is given twice; expected each name once");
  fs::remove_all(dir);
}

}  // namespace

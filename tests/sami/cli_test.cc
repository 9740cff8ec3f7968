// `cradle sami`: commands run, a stopped run exits 130 with a checkpoint that resumes, and wrong
// input is a one-line error with exit status 1.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "fixture.h"

namespace {

namespace fs = std::filesystem;

using cradle::test::read_lines;
using cradle::test::run_cradle;
using cradle::test::RunResult;

TEST(SamiCli, InfoAndRandomRun) {
  const RunResult info = run_cradle("sami info --env PandaPush");
  EXPECT_EQ(info.status, 0) << info.out;
  EXPECT_NE(info.out.find("cell friction 30, cube mass 30"), std::string::npos);
  const RunResult random = run_cradle(
      "sami random --env CrippleAnt --split extreme --episodes 2 --max-steps 5 --seed 1");
  EXPECT_EQ(random.status, 0) << random.out;
  EXPECT_NE(random.out.find("episode 1: return"), std::string::npos);
}

// SIGTERM (a scheduler's time limit) ends `sami train` with a checkpoint and exit 130, not 0, so
// no launcher takes the run for finished; --resume then continues it.
TEST(SamiCli, StopSignalSavesAndExits130) {
  const fs::path dir = cradle::test::fresh_dir("sami_cli_stop");
  const std::string args =
      "sami train --env PandaPush --method CCM --seed 1 --no-progress --out " + dir.string() +
      " --hp net_arch=32,32 --hp lstm_hidden=16 --hp batch_size=4 --hp contrast_batch_size=4"
      " --hp buffer_size=8 --hp train_freq=50 --hp gradient_steps=1 --hp learning_starts=60";
  RunResult r = cradle::test::run_cradle_then_signal(args + " --steps-per-env 1000000",
                                                     dir / "progress.csv", "TERM");
  ASSERT_EQ(r.status, 130) << r.out;
  EXPECT_NE(r.out.find("stopped by a signal; continue with: cradle sami train --out"),
            std::string::npos)
      << r.out;
  ASSERT_TRUE(fs::exists(dir / "checkpoint.ckpt"));
  // The row at the stop is the last one; resuming runs on to one more row.
  const std::vector<std::string> rows = read_lines(dir / "progress.csv");
  ASSERT_GE(rows.size(), 2u);
  const long stopped_at = std::stol(rows.back().substr(0, rows.back().find(',')));
  EXPECT_LT(stopped_at, 6'000'000);
  r = run_cradle("sami train --out " + dir.string() + " --resume --no-progress --steps-per-env " +
                 std::to_string(stopped_at / 6 + 50));
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_GT(read_lines(dir / "progress.csv").size(), rows.size());
  fs::remove_all(dir);
}

TEST(SamiCli, WrongInputIsOneLineError) {
  for (const char* args : {"sami random --env Cheetah", "sami random --env Ant --split hard",
                           "sami bench --env Nope", "sami random --split missing.yml"}) {
    const RunResult out = run_cradle(args);
    EXPECT_EQ(out.status, 1) << args;
    EXPECT_EQ(out.out.rfind("cradle: error: ", 0), 0u) << out.out;
    EXPECT_EQ(out.out.find('\n'), out.out.size() - 1) << out.out;
  }
}

}  // namespace

// Every env family through the one run path survives kill -9: a `cradle train --env ID` run killed
// after a checkpoint and resumed ends with the same files as an uninterrupted run (PPO: progress
// rows and the final checkpoint byte for byte), for a MIMo sample task, a TeachMyAgent walker and
// a SaMI robot.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fixture.h"

namespace {

namespace fs = std::filesystem;

using cradle::test::read_lines;
using cradle::test::run_cradle;

std::string read_bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string train_args(const std::string& id, const fs::path& dir) {
  return "train --env " + id + " --save-dir " + dir.string() +
         " --algo ppo --envs 2 --threads 2 --intrinsic '' --hp n_steps=64 --hp batch_size=64"
         " --hp n_epochs=1 --checkpoint-every 256 --eval-episodes 0 --seed 7";
}

// progress.csv without the columns that measure time (time, charts/SPS, perf/*).
std::vector<std::string> progress_values(const fs::path& dir) {
  std::vector<std::string> out;
  for (const std::string& line : read_lines(dir / "logs" / "progress.csv")) {
    std::vector<std::string> cells;
    size_t at = 0;
    for (;;) {
      const size_t comma = line.find(',', at);
      cells.push_back(line.substr(at, comma == std::string::npos ? comma : comma - at));
      if (comma == std::string::npos) break;
      at = comma + 1;
    }
    std::string kept;
    for (size_t c = 0; c + 2 < cells.size(); ++c)
      if (c != 1 && c != 2) kept += cells[c] + ",";
    out.push_back(kept);
  }
  return out;
}

class ResumeFamily : public testing::TestWithParam<const char*> {};

TEST_P(ResumeFamily, KillNineThenResumeEqualsUninterruptedRun) {
  const std::string id = GetParam();
  const std::string tag = "resume_family_" + std::to_string(std::hash<std::string>{}(id) % 100000);
  const fs::path killed = cradle::test::fresh_dir(tag + "_killed");
  const fs::path whole = cradle::test::fresh_dir(tag + "_whole");
  // Past the first checkpoint (256 steps) by at least one more rollout, then SIGKILL: whenever
  // that happens, the resumed run must end as the uninterrupted one.
  const bool ready =
      cradle::test::run_cradle_then_kill(train_args(id, killed) + " --steps 1000000", [&] {
        return fs::exists(killed / "checkpoints" / "latest.ckpt") &&
               read_lines(killed / "logs" / "progress.csv").size() >= 4;
      });
  ASSERT_TRUE(ready) << id << ": training never passed its first checkpoint";

  cradle::test::RunResult r = run_cradle(train_args(id, killed) + " --steps 1024 --resume");
  ASSERT_EQ(r.status, 0) << r.out;
  r = run_cradle(train_args(id, whole) + " --steps 1024");
  ASSERT_EQ(r.status, 0) << r.out;

  // Every rollout once, in order, with the uninterrupted run's values; the same networks.
  const std::vector<std::string> rows = progress_values(killed);
  ASSERT_EQ(rows.size(), 1u + 1024 / 128) << id;
  EXPECT_EQ(rows, progress_values(whole)) << id;
  EXPECT_EQ(read_bytes(killed / "checkpoints" / "final.ckpt"),
            read_bytes(whole / "checkpoints" / "final.ckpt"))
      << id;
  fs::remove_all(killed);
  fs::remove_all(whole);
}

INSTANTIATE_TEST_SUITE_P(Families, ResumeFamily,
                         testing::Values("mimo/reach", "tma/stump-tracks:old_classic_bipedal",
                                         "sami/CrippleHalfCheetah:train"));

}  // namespace

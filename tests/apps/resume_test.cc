// Interrupted and resumed training end to end: kill -9 after a checkpoint, then --resume, equals
// an uninterrupted run (logs, progress, final checkpoint); damaged checkpoints, a write error and
// contradicting flags are one-line errors.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "fixture.h"

namespace {

namespace fs = std::filesystem;

using CliRun = cradle::test::RunResult;
using cradle::test::read_lines;
using cradle::test::run_cradle;

CliRun run_shell(const std::string& command) { return cradle::test::run(command + " 2>&1"); }

fs::path temp_dir(const std::string& tag) { return cradle::test::fresh_dir("resume_" + tag); }

std::string read_text(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

using cradle::test::message_lines;

// A quick self-touch training config (no vision, 100-step episodes) writing to dir/run.
std::string training_config(const fs::path& dir) {
  return cradle::test::self_touch_config(dir, 100, "save_logs_every: 1000\n");
}

std::string train_args(const fs::path& dir) {
  return "train --config " + training_config(dir) +
         " --envs 2 --threads 2 --intrinsic body_part_novelty --hp n_steps=64 batch_size=64"
         " n_epochs=1 --eval-episodes 0 --checkpoint-every 256 --no-eval-video --seed 7";
}

// training.jsonl entries without their wall time (the only field that depends on the clock).
std::vector<nlohmann::json> log_entries(const fs::path& run) {
  std::vector<nlohmann::json> entries;
  for (const std::string& line : read_lines(run / "logs" / "training.jsonl")) {
    nlohmann::json j = nlohmann::json::parse(line);
    j.erase("wall_time");
    entries.push_back(j);
  }
  return entries;
}

// progress.csv's step and loss columns (time, steps/s and perf seconds depend on the clock).
std::vector<std::string> progress_values(const fs::path& run) {
  std::vector<std::string> values;
  for (const std::string& line : read_lines(run / "logs" / "progress.csv")) {
    std::vector<std::string> cells;
    size_t at = 0;
    for (;;) {
      const size_t comma = line.find(',', at);
      cells.push_back(line.substr(at, comma == std::string::npos ? comma : comma - at));
      if (comma == std::string::npos) break;
      at = comma + 1;
    }
    std::string kept;
    for (size_t c = 0; c + 2 < cells.size(); ++c) {
      if (c == 1 || c == 2) continue;  // time, charts/SPS
      kept += cells[c] + ",";
    }
    values.push_back(kept);
  }
  return values;
}

// Starts training, kills it with SIGKILL once it has a checkpoint and has gone past it, resumes:
// the logs continue without loss or duplicates and match an uninterrupted run's, and the final
// checkpoints are byte-identical.
TEST(Resume, KillNineThenResumeEqualsUninterruptedRun) {
  const fs::path killed = temp_dir("killed");
  const fs::path whole = temp_dir("whole");
  // Past the first checkpoint (256) by at least one more rollout, then SIGKILL.
  const bool ready =
      cradle::test::run_cradle_then_kill(train_args(killed) + " --steps 100000", [&] {
        return fs::exists(killed / "run" / "checkpoints" / "latest.ckpt") &&
               read_lines(killed / "run" / "logs" / "progress.csv").size() >= 4;
      });
  ASSERT_TRUE(ready) << "training never passed its first checkpoint";
  const std::vector<nlohmann::json> before_kill = log_entries(killed / "run");

  CliRun r = run_cradle(train_args(killed) + " --steps 1024 --resume");
  ASSERT_EQ(r.status, 0) << r.out;
  r = run_cradle(train_args(whole) + " --steps 1024");
  ASSERT_EQ(r.status, 0) << r.out;

  // progress.csv: every rollout once, steps strictly increasing, values as uninterrupted.
  std::vector<long> steps;
  for (const std::string& line : read_lines(killed / "run" / "logs" / "progress.csv")) {
    if (line.starts_with("global_step")) continue;
    steps.push_back(std::stol(line.substr(0, line.find(','))));
  }
  const std::vector<long> expected = {128, 256, 384, 512, 640, 768, 896, 1024};
  EXPECT_EQ(steps, expected);
  EXPECT_EQ(progress_values(killed / "run"), progress_values(whole / "run"));

  // training.jsonl: the episodes before the checkpoint kept, none twice, as uninterrupted.
  const std::vector<nlohmann::json> resumed = log_entries(killed / "run");
  const std::vector<nlohmann::json> uninterrupted = log_entries(whole / "run");
  ASSERT_GT(resumed.size(), 2u);
  EXPECT_EQ(resumed, uninterrupted);
  for (size_t k = 0; k < before_kill.size() && k < resumed.size(); ++k) {
    // What the killed run wrote up to its checkpoint is the resumed log's start.
    if (before_kill[k] != resumed[k]) {
      EXPECT_TRUE(fs::exists(killed / "run" / "logs" / "training.after-checkpoint.jsonl"));
      break;
    }
  }
  EXPECT_EQ(read_text(killed / "run" / "checkpoints" / "final.ckpt"),
            read_text(whole / "run" / "checkpoints" / "final.ckpt"));
  fs::remove_all(killed);
  fs::remove_all(whole);
}

// SIGTERM (a scheduler's time limit) ends training at its next update with a checkpoint and exit
// 130; --resume continues from exactly that step.
TEST(Resume, StopSignalSavesAndExits130) {
  const fs::path dir = temp_dir("stopped");
  CliRun r = cradle::test::run_cradle_then_signal(
      train_args(dir) + " --steps 10000000", dir / "run" / "checkpoints" / "latest.ckpt", "TERM");
  ASSERT_EQ(r.status, 130) << r.out;
  EXPECT_NE(r.out.find(" — interrupted"), std::string::npos) << r.out;
  const std::vector<std::string> rows = read_lines(dir / "run" / "logs" / "progress.csv");
  ASSERT_GE(rows.size(), 2u);
  const long stopped_at = std::stol(rows.back().substr(0, rows.back().find(',')));
  ASSERT_LT(stopped_at, 10'000'000);
  r = run_cradle(train_args(dir) + " --steps " + std::to_string(stopped_at + 256) + " --resume");
  ASSERT_EQ(r.status, 0) << r.out;
  const std::vector<std::string> resumed = read_lines(dir / "run" / "logs" / "progress.csv");
  EXPECT_EQ(resumed.size(), rows.size() + 2);  // two more rollouts of 128 steps
  fs::remove_all(dir);
}

// Truncated or altered checkpoints are refused with one line by resume and by evaluate.
TEST(Resume, DamagedCheckpointsAreOneLineErrors) {
  const fs::path dir = temp_dir("damaged");
  CliRun r = run_cradle(train_args(dir) + " --steps 256");
  ASSERT_EQ(r.status, 0) << r.out;
  const fs::path latest = dir / "run" / "checkpoints" / "latest.ckpt";
  const std::string good = read_text(latest);
  ASSERT_GT(good.size(), 1000u);
  const std::vector<std::string> damaged = {good.substr(0, good.size() / 2),
                                            good.substr(0, 10),
                                            "",
                                            good.substr(0, good.size() - 1),
                                            [&] {
                                              std::string s = good;
                                              s[s.size() / 3] ^= 0x10;
                                              return s;
                                            }(),
                                            [&] {
                                              std::string s = good;
                                              s[s.size() - 20] ^= 0x01;
                                              return s;
                                            }(),
                                            "PK\x03\x04 not a checkpoint"};
  for (const std::string& bytes : damaged) {
    std::ofstream(latest, std::ios::binary | std::ios::trunc) << bytes;
    r = run_cradle(train_args(dir) + " --steps 512 --resume");
    EXPECT_EQ(r.status, 1) << r.out;
    const std::vector<std::string> lines = message_lines(r.out);
    ASSERT_EQ(lines.size(), 1u) << r.out;
    EXPECT_TRUE(lines[0].starts_with("cradle: error: ")) << r.out;
  }
  fs::remove_all(dir);
}

// A write error during a checkpoint (here a file-size limit, as a full disk would): one line,
// exit 1, the previous checkpoint intact, no temp file, the training log flushed.
TEST(Resume, CheckpointWriteErrorKeepsPreviousCheckpoint) {
  const fs::path dir = temp_dir("full");
  CliRun r = run_cradle(train_args(dir) + " --steps 256");
  ASSERT_EQ(r.status, 0) << r.out;
  const fs::path latest = dir / "run" / "checkpoints" / "latest.ckpt";
  const std::string before = read_text(latest);
  const long log_size = static_cast<long>(fs::file_size(dir / "run" / "logs" / "training.jsonl"));
  // A limit (1 KiB blocks) below the checkpoint's size, above every other file's.
  const long limit_kib = static_cast<long>(before.size()) / 1024 - 1;
  ASSERT_GT(limit_kib * 1024, 4 * log_size + 65536) << "checkpoint too small for this test";
  r = run_shell("trap '' XFSZ; ulimit -f " + std::to_string(limit_kib) + "; exec " + CRADLE_BINARY +
                " " + train_args(dir) + " --steps 512 --resume");
  EXPECT_EQ(r.status, 1) << r.out;
  const std::vector<std::string> lines = message_lines(r.out);
  ASSERT_EQ(lines.size(), 1u) << r.out;
  EXPECT_NE(lines[0].find("cannot write"), std::string::npos) << r.out;
  EXPECT_EQ(read_text(latest), before);
  for (const auto& entry : fs::directory_iterator(dir / "run" / "checkpoints")) {
    EXPECT_FALSE(entry.path().string().ends_with(".tmp")) << entry.path();
    EXPECT_FALSE(entry.path().string().ends_with(".part")) << entry.path();
  }
  EXPECT_GT(static_cast<long>(fs::file_size(dir / "run" / "logs" / "training.jsonl")), log_size);
  // And the run resumes from the intact checkpoint.
  r = run_cradle(train_args(dir) + " --steps 512 --resume");
  EXPECT_EQ(r.status, 0) << r.out;
  fs::remove_all(dir);
}

// --resume keeps the checkpoint's algorithm: another --algo is refused; --hp values apply.
TEST(Resume, ContradictingAlgoIsRefused) {
  const fs::path dir = temp_dir("algo");
  CliRun r = run_cradle(train_args(dir) + " --steps 128");
  ASSERT_EQ(r.status, 0) << r.out;
  r = run_cradle(train_args(dir) + " --steps 256 --resume --algo a2c");
  EXPECT_EQ(r.status, 1) << r.out;
  const std::vector<std::string> lines = message_lines(r.out);
  ASSERT_EQ(lines.size(), 1u) << r.out;
  EXPECT_NE(lines[0].find("ppo"), std::string::npos) << r.out;
  r = run_cradle(train_args(dir) + " --steps 256 --resume --hp learning_rate=0.0001");
  EXPECT_EQ(r.status, 0) << r.out;
  const std::vector<std::string> rows = read_lines(dir / "run" / "logs" / "progress.csv");
  EXPECT_NE(rows.back().find(",0.0001,"), std::string::npos) << rows.back();
  fs::remove_all(dir);
}

// The intrinsic rewards are part of the learned task: a resume under other rewards is one line
// naming both, the same rewards continue.
TEST(Resume, ContradictingIntrinsicIsRefused) {
  const fs::path dir = temp_dir("intrinsic");
  CliRun r = run_cradle(train_args(dir) + " --steps 128");
  ASSERT_EQ(r.status, 0) << r.out;
  std::string other = train_args(dir);
  other.replace(other.find("--intrinsic body_part_novelty"), 29, "--intrinsic touch_count:2");
  r = run_cradle(other + " --steps 256 --resume");
  EXPECT_EQ(r.status, 1) << r.out;
  const std::vector<std::string> lines = message_lines(r.out);
  ASSERT_EQ(lines.size(), 1u) << r.out;
  EXPECT_NE(lines[0].find("'body_part_novelty:1'"), std::string::npos) << r.out;
  EXPECT_NE(lines[0].find("'touch_count:2'"), std::string::npos) << r.out;
  r = run_cradle(train_args(dir) + " --steps 256 --resume");
  EXPECT_EQ(r.status, 0) << r.out;
  fs::remove_all(dir);
}

}  // namespace

// `cradle train --async-batch K` end to end: PPO collects through the async
// vector on a small self-touch config with intrinsic rewards; the training log holds every
// episode once (as many entries of as many steps as the lock-step run's, since each env fills the
// same rows of each rollout), checkpoints are episode boundaries, --resume continues, a sample env
// trains too, and wrong values are one-line errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fixture.h"

namespace {

namespace fs = std::filesystem;

using cradle::test::read_lines;
using cradle::test::run_cradle;
using cradle::test::RunResult;

// A quick self-touch config (no vision, 10-step episodes) writing to dir/run.
std::string training_config(const fs::path& dir) {
  return cradle::test::self_touch_config(dir, 10, "save_logs_every: 1000\n");
}

// 3 envs, 16-step rollouts (48 env steps), a checkpoint every 96.
std::string train_args(const fs::path& dir) {
  return "train --config " + training_config(dir) +
         " --envs 3 --threads 2 --intrinsic body_part_novelty,episode_coverage --hp n_steps=16"
         " batch_size=48 n_epochs=1 --eval-episodes 0 --checkpoint-every 96 --seed 3";
}

// Entries of training.jsonl per episode length.
std::map<int, int> lengths(const fs::path& run) {
  std::map<int, int> count;
  for (const std::string& line : read_lines(run / "logs" / "training.jsonl")) {
    ++count[nlohmann::json::parse(line).at("steps").get<int>()];
  }
  return count;
}

// The first cell of each progress.csv row.
std::vector<long> progress_steps(const fs::path& run) {
  std::vector<long> steps;
  for (const std::string& line : read_lines(run / "logs" / "progress.csv")) {
    if (!line.starts_with("global_step"))
      steps.push_back(std::stol(line.substr(0, line.find(','))));
  }
  return steps;
}

TEST(AsyncTrain, PpoOnSelfTouchLogsEveryEpisodeOnceCheckpointsAndResumes) {
  const fs::path async = cradle::test::fresh_dir("async_train");
  const fs::path lockstep = cradle::test::fresh_dir("async_train_lockstep");
  RunResult r = run_cradle(train_args(async) + " --async-batch 2 --steps 192");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("trained 192 env steps"), std::string::npos) << r.out;
  r = run_cradle(train_args(lockstep) + " --steps 192");
  ASSERT_EQ(r.status, 0) << r.out;

  // Per env: the first reset's 0-step entry, then 10-step episodes, each with its autoreset row:
  // 32 rows per env per learn() call are 3 episodes, the last recorded at the checkpoint.
  const std::map<int, int> expected = {{0, 3}, {10, 18}};
  EXPECT_EQ(lengths(async / "run"), expected);
  EXPECT_EQ(lengths(lockstep / "run"), expected);
  EXPECT_EQ(progress_steps(async / "run"), (std::vector<long>{48, 96, 144, 192}));
  for (const char* file : {"step_96.ckpt", "latest.ckpt", "final.ckpt"}) {
    EXPECT_TRUE(fs::exists(async / "run" / "checkpoints" / file)) << file;
  }
  // Every entry is a self-touch episode with its score.
  for (const std::string& line : read_lines(async / "run" / "logs" / "training.jsonl")) {
    const nlohmann::json e = nlohmann::json::parse(line);
    EXPECT_TRUE(e.contains("right_hand_touches") && e.contains("score")) << line;
  }

  // --resume continues the log from the checkpoint's episodes: 3 more episodes per env.
  r = run_cradle(train_args(async) + " --async-batch 2 --steps 288 --resume");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(lengths(async / "run"), (std::map<int, int>{{0, 3}, {10, 27}}));
  EXPECT_EQ(progress_steps(async / "run"), (std::vector<long>{48, 96, 144, 192, 240, 288}));
  fs::remove_all(async);
  fs::remove_all(lockstep);
}

TEST(AsyncTrain, SampleEnvTrainsWithAsyncCollection) {
  const fs::path dir = cradle::test::fresh_dir("async_train_reach");
  const RunResult r = run_cradle(
      "train --env reach --algo a2c --envs 2 --threads 2 --async-batch 1 --steps 160 --hp "
      "n_steps=16 --save-dir " +
      (dir / "run").string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("trained 160 env steps"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(dir / "run" / "checkpoints" / "final.ckpt"));
  fs::remove_all(dir);
}

TEST(AsyncTrain, WrongValuesAreOneLineErrors) {
  const fs::path dir = cradle::test::fresh_dir("async_train_errors");
  const std::string base = "train --config " + training_config(dir) + " --steps 64";
  for (const std::string& args : std::vector<std::string>{
           base + " --envs 2 --async-batch 2", base + " --envs 2 --async-batch 0",
           base + " --envs 2 --async-batch -1", base + " --envs 1 --async-batch 1",
           base + " --envs 2 --async-batch 1 --algo sac",
           base + " --envs 2 --async-batch 1 --algo td3",
           base + " --envs 2 --async-batch 1 --algo ddpg",
           base + " --envs 2 --async-batch 1 --hp normalize_returns=true"}) {
    const RunResult r = run_cradle(args);
    EXPECT_EQ(r.status, 1) << args << ": " << r.out;
    EXPECT_EQ(r.out.rfind("cradle: error: ", 0), 0u) << args << ": " << r.out;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << args << ": " << r.out;
  }
  EXPECT_NE(run_cradle(base + " --envs 2 --async-batch 2").out.find("between 1 and --envs - 1 (1)"),
            std::string::npos);
  fs::remove_all(dir);
}

}  // namespace

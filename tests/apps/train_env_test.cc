// `cradle train --env ID`: envs by id trained by the one training loop, with a curriculum from a
// task-space file: progress.csv, checkpoints and the teacher's book, continued by --resume;
// BabyBench-only flags, unknown envs and folders that hold a run are one-line errors; run.py's
// budget unit.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fixture.h"

namespace {

namespace fs = std::filesystem;

using cradle::test::read_lines;
using cradle::test::run_cradle;
using cradle::test::RunResult;

// The first cell of a CSV line as a number.
double first_cell(const std::string& line) { return std::stod(line.substr(0, line.find(','))); }

TEST(TrainEnv, CatchCurriculumTrainsWritesTheBooksAndResumes) {
  const fs::path dir = cradle::test::fresh_dir("train_env_catch");
  const std::string file = std::string(CRADLE_SOURCE_DIR) + "/configs/curricula/mimo_catch.yml";
  const std::string args = "train --env catch --task-space " + file +
                           " --teacher ALP-GMM --algo ppo --envs 1 --checkpoint-every 256 "
                           "--hp n_steps=128 --hp batch_size=64 --hp pi_layers=16 "
                           "--hp vf_layers=16 --save-dir " +
                           (dir / "run").string();
  RunResult r = run_cradle(args + " --steps 512");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("trained 512 env steps"), std::string::npos) << r.out;

  // progress.csv: one row per update (128 steps), up to 512.
  std::vector<std::string> progress = read_lines(dir / "run" / "logs" / "progress.csv");
  ASSERT_EQ(progress.size(), 1u + 4);
  EXPECT_EQ(progress[0].rfind("global_step,time,", 0), 0u);
  EXPECT_EQ(first_cell(progress.back()), 512);
  EXPECT_TRUE(fs::exists(dir / "run" / "checkpoints" / "final.ckpt"));
  EXPECT_TRUE(fs::exists(dir / "run" / "checkpoints" / "step_256.ckpt"));
  EXPECT_FALSE(fs::exists(dir / "run" / "logs" / "training.jsonl"));  // BabyBench's log only

  // The teacher's book: every training episode with its task inside the file's box, in order,
  // and the teacher's dump at the end.
  auto read_book = [&](long& train, long& dumps) {
    train = 0;
    dumps = 0;
    for (const std::string& line : read_lines(dir / "run" / "logs" / "teacher.jsonl")) {
      const nlohmann::json j = nlohmann::json::parse(line);
      if (j["kind"] == "train") {
        EXPECT_EQ(j["episode"], train++);
        const auto task = j["task"].get<std::vector<double>>();
        EXPECT_EQ(task.size(), 3u);
        EXPECT_GE(task[1], 0.0);  // ball_speed in [0, 2]
        EXPECT_LE(task[1], 2.0);
      } else {
        EXPECT_EQ(j["kind"], "dump");
        EXPECT_EQ(j["teacher"]["teacher"], "alp_gmm");
        ++dumps;
      }
    }
  };
  long train = 0, dumps = 0;
  read_book(train, dumps);
  EXPECT_GT(train, 2);  // a dropped ball ends an episode within a few dozen steps
  EXPECT_EQ(dumps, 1);

  // --resume continues the run, the progress rows and the book (episodes numbered on).
  r = run_cradle(args + " --steps 768 --resume");
  ASSERT_EQ(r.status, 0) << r.out;
  progress = read_lines(dir / "run" / "logs" / "progress.csv");
  ASSERT_EQ(progress.size(), 1u + 6);
  EXPECT_EQ(first_cell(progress.back()), 768);
  long more = 0;
  read_book(more, dumps);
  EXPECT_GT(more, train);
  EXPECT_EQ(dumps, 2);
}

// A run killed after its checkpoint at 256 steps, its teacher's book already 512 steps long (made
// here by putting the step-256 checkpoint back as latest.ckpt): the resume cuts the book back to
// the checkpoint, keeps the later lines aside, and books the replayed steps' episodes once, the
// teacher counting its steps on from the checkpoint's.
TEST(TrainEnv, AResumeCutsTheTeachersBookBackToItsCheckpoint) {
  const fs::path dir = cradle::test::fresh_dir("train_env_book");
  const std::string file = std::string(CRADLE_SOURCE_DIR) + "/configs/curricula/mimo_catch.yml";
  const std::string args = "train --env catch --task-space " + file +
                           " --teacher ALP-GMM --algo ppo --envs 2 --checkpoint-every 256 "
                           "--hp n_steps=64 --hp batch_size=64 --hp pi_layers=16 "
                           "--hp vf_layers=16 --eval-episodes 0 --save-dir " +
                           (dir / "run").string();
  RunResult r = run_cradle(args + " --steps 512");
  ASSERT_EQ(r.status, 0) << r.out;
  const fs::path book = dir / "run" / "logs" / "teacher.jsonl";
  const std::vector<std::string> whole = read_lines(book);
  const fs::path checkpoints = dir / "run" / "checkpoints";
  fs::copy_file(checkpoints / "step_256.ckpt", checkpoints / "latest.ckpt",
                fs::copy_options::overwrite_existing);
  fs::remove(checkpoints / "final.ckpt");

  r = run_cradle(args + " --steps 512 --resume");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("teacher.jsonl: lines after the checkpoint kept in"), std::string::npos)
      << r.out;
  // What the first run booked after the checkpoint is kept aside, its dump last.
  const std::vector<std::string> aside =
      read_lines(dir / "run" / "logs" / "teacher.after-checkpoint.jsonl");
  ASSERT_GT(aside.size(), 1u);
  ASSERT_LT(aside.size(), whole.size());
  const size_t kept = whole.size() - aside.size();
  EXPECT_EQ(std::vector<std::string>(whole.begin() + kept, whole.end()), aside);
  // The book up to the checkpoint, then every later episode once, numbered on, its step count
  // past the checkpoint's; one teacher dump, at the end.
  const std::vector<std::string> resumed = read_lines(book);
  ASSERT_GT(resumed.size(), kept);
  EXPECT_EQ(std::vector<std::string>(resumed.begin(), resumed.begin() + kept),
            std::vector<std::string>(whole.begin(), whole.begin() + kept));
  long train = 0, dumps = 0;
  for (const std::string& line : resumed) {
    const nlohmann::json j = nlohmann::json::parse(line);
    if (j["kind"] == "train") {
      EXPECT_EQ(j["episode"], train++) << line;
    } else {
      ++dumps;
    }
  }
  EXPECT_EQ(dumps, 1);
  const nlohmann::json dump = nlohmann::json::parse(resumed.back());
  EXPECT_EQ(dump["kind"], "dump");
  // The teacher counts the steps its envs took: the run's 512 but the autoreset steps, one after
  // each episode (the last ones of the two envs may have had none).
  EXPECT_NEAR(dump["env_steps"].get<long>(), 512 - train, 2) << resumed.back();
}

// `--teacher` without a task-space file: TeachMyAgent's benchmark curriculum over Stump Tracks,
// its teacher starting from the easy corner (no stumps, wide spacing) as high expert knowledge has
// it, within the benchmark's bounds.
TEST(TrainEnv, ATeacherAloneRunsTheFamilysCurriculum) {
  const fs::path dir = cradle::test::fresh_dir("train_env_teacher");
  const RunResult r = run_cradle(
      "train --env tma/stump-tracks:old_classic_bipedal --teacher ALP-GMM --algo ppo --envs 4 "
      "--steps 8192 --hp n_steps=256 --hp batch_size=64 --hp pi_layers=16 --hp vf_layers=16 "
      "--eval-episodes 0 --save-dir " +
      (dir / "run").string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("teacher.jsonl"), std::string::npos) << r.out;
  long train = 0;
  for (const std::string& line : read_lines(dir / "run" / "logs" / "teacher.jsonl")) {
    const nlohmann::json j = nlohmann::json::parse(line);
    if (j["kind"] == "dump") {
      EXPECT_EQ(j["teacher"]["maxs"], nlohmann::json::parse("[3.0, 6.0]")) << line;
      continue;
    }
    ++train;
    const auto task = j["task"].get<std::vector<double>>();
    ASSERT_EQ(task.size(), 2u) << line;
    EXPECT_GE(task[0], 0.0) << line;  // stump height, near 0
    EXPECT_LE(task[0], 1.5) << line;
    EXPECT_GE(task[1], 3.0) << line;  // obstacle spacing, near 6
    EXPECT_LE(task[1], 6.0) << line;
  }
  EXPECT_GE(train, 4);  // each env's first episode, 2,000 steps at most
  // TeachMyAgent's envs score no behaviour: the return's chart only, no empty score chart.
  std::ifstream figures(dir / "run" / "plots" / "figures.json");
  const std::string listed{std::istreambuf_iterator<char>(figures), {}};
  EXPECT_NE(listed.find("learning_curve_return.png"), std::string::npos) << listed;
  EXPECT_EQ(listed.find("learning_curve_score"), std::string::npos) << listed;
  fs::remove_all(dir);
}

// --reset-every: a fresh learner every N env steps in any run, the run's step count going on; the
// checkpoint records the resets, so a resumed run continues the second learner.
TEST(TrainEnv, ResetEveryStartsFreshLearnersAndResumes) {
  const fs::path dir = cradle::test::fresh_dir("train_env_reset");
  const std::string args =
      "train --env mimo/reach --algo ppo --envs 1 --reset-every 128 --checkpoint-every 64 "
      "--intrinsic '' --eval-episodes 0 --hp n_steps=32 --hp batch_size=32 --hp pi_layers=8 "
      "--hp vf_layers=8 --save-dir " +
      (dir / "run").string();
  RunResult r = run_cradle(args + " --steps 192");
  ASSERT_EQ(r.status, 0) << r.out;
  // One row per update, the run's steps going on across the reset at 128.
  std::vector<std::string> progress = read_lines(dir / "run" / "logs" / "progress.csv");
  ASSERT_EQ(progress.size(), 1u + 6);
  for (size_t k = 1; k < progress.size(); ++k) EXPECT_EQ(first_cell(progress[k]), 32.0 * k);
  std::ifstream in(dir / "run" / "checkpoints" / "final.ckpt", std::ios::binary);
  const std::string ckpt{std::istreambuf_iterator<char>(in), {}};
  EXPECT_NE(ckpt.find("\"learner_resets\":1"), std::string::npos);
  EXPECT_NE(ckpt.find("\"step_offset\":128"), std::string::npos);
  EXPECT_NE(ckpt.find("\"steps\":64"), std::string::npos);  // the second learner's own
  const nlohmann::json run = nlohmann::json::parse(std::ifstream(dir / "run" / "run.json"));
  EXPECT_EQ(run["reset_every"], 128);
  r = run_cradle(args + " --steps 320 --resume");
  ASSERT_EQ(r.status, 0) << r.out;
  progress = read_lines(dir / "run" / "logs" / "progress.csv");
  ASSERT_EQ(progress.size(), 1u + 10);
  EXPECT_EQ(first_cell(progress.back()), 320);
  std::ifstream again(dir / "run" / "checkpoints" / "final.ckpt", std::ios::binary);
  const std::string resumed{std::istreambuf_iterator<char>(again), {}};
  EXPECT_NE(resumed.find("\"learner_resets\":2"), std::string::npos);
  EXPECT_NE(resumed.find("\"step_offset\":256"), std::string::npos);
  fs::remove_all(dir);
}

TEST(TrainEnv, WrongCombinationsAreOneLineErrors) {
  const fs::path dir = cradle::test::fresh_dir("train_env_errors");
  const std::string config = cradle::test::config_path("config_selftouch.yml").string();
  for (const std::string& args : std::vector<std::string>{
           "train", "train --env fly", "train --env reach --config " + config,
           "train --env tma/parkour", "train --env reach --randomize-start",
           "train --env reach --compare-random", "train --env reach --no-eval-video",
           "train --env standup --teacher Random"}) {
    const RunResult r = run_cradle(args + " --steps 64", dir);
    EXPECT_EQ(r.status, 1) << args << ": " << r.out;
    EXPECT_EQ(r.out.rfind("cradle: error: ", 0), 0u) << args << ": " << r.out;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << args << ": " << r.out;
  }
  EXPECT_FALSE(fs::exists(dir / "results"));  // nothing written
  // The unknown env names the closest ids.
  EXPECT_NE(run_cradle("train --env mimo/rech", dir).out.find("closest: mimo/reach"),
            std::string::npos);
}

// A folder that holds a run is refused without --resume or --overwrite, whatever the family, and
// left as it was; --overwrite replaces it.
TEST(TrainEnv, AFinishedRunIsNeverReplacedSilently) {
  const fs::path dir = cradle::test::fresh_dir("train_env_overwrite");
  for (const char* env : {"tma/stump-tracks:old_classic_bipedal", "sami/Hopper"}) {
    const std::string args =
        std::string("train --env ") + env +
        " --algo ppo --envs 1 --steps 64 --hp n_steps=32 --hp batch_size=32 --save-dir run";
    ASSERT_EQ(run_cradle(args, dir).status, 0) << env;
    const std::vector<std::string> before = read_lines(dir / "run" / "logs" / "progress.csv");
    const RunResult again = run_cradle(args + " --seed 9", dir);
    EXPECT_EQ(again.status, 1) << again.out;
    EXPECT_EQ(std::count(again.out.begin(), again.out.end(), '\n'), 1) << again.out;
    EXPECT_NE(again.out.find("--resume"), std::string::npos) << again.out;
    EXPECT_NE(again.out.find("--overwrite"), std::string::npos) << again.out;
    EXPECT_EQ(read_lines(dir / "run" / "logs" / "progress.csv"), before);
    // Continuing and replacing at once is refused too.
    const RunResult both = run_cradle(args + " --resume --overwrite", dir);
    EXPECT_EQ(both.status, 1) << both.out;
    EXPECT_EQ(std::count(both.out.begin(), both.out.end(), '\n'), 1) << both.out;
    EXPECT_EQ(read_lines(dir / "run" / "logs" / "progress.csv"), before);
    // `cradle evaluate --run`'s files measured this run: --overwrite removes them with it.
    std::ofstream(dir / "run" / "evaluation_final.json") << "{}\n";
    fs::create_directories(dir / "run" / "videos");
    std::ofstream(dir / "run" / "evaluation_notes.txt") << "the user's own\n";  // not the run's
    const RunResult replaced = run_cradle(args + " --seed 9 --overwrite", dir);
    EXPECT_EQ(replaced.status, 0) << replaced.out;
    EXPECT_NE(read_lines(dir / "run" / "logs" / "progress.csv"), before);
    EXPECT_FALSE(fs::exists(dir / "run" / "evaluation_final.json"));
    EXPECT_FALSE(fs::exists(dir / "run" / "videos"));
    EXPECT_TRUE(fs::exists(dir / "run" / "evaluation_notes.txt"));
    // A folder whose only trace of a run is its evaluation is still refused, naming the file.
    fs::remove_all(dir / "run" / "checkpoints");
    fs::remove_all(dir / "run" / "logs");
    const RunResult evaluated = run_cradle(args, dir);
    EXPECT_EQ(evaluated.status, 1) << evaluated.out;
    EXPECT_NE(evaluated.out.find("evaluation.json"), std::string::npos) << evaluated.out;
    fs::remove_all(dir / "run");
  }
}

// run.py's budget is in millions of env steps: a value meant as plain steps is refused, naming
// the unit and what to give instead; nothing is written.
TEST(TmaRunFlags, NbEnvStepsIsInMillions) {
  const fs::path dir = cradle::test::fresh_dir("tma_run_millions");
  const RunResult r = run_cradle("tma run --nb_env_steps 20000 --out run", dir);
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
  EXPECT_NE(r.out.find("in millions"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("give 0.02"), std::string::npos) << r.out;
  EXPECT_FALSE(fs::exists(dir / "run"));
}

}  // namespace

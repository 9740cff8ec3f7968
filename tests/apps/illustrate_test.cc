// `cradle illustrate` and `cradle bench --env` end to end: flag errors, saved models, progress,
// videos, loading a saved model, and the sample env benchmark.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fixture.h"
#include "learn/registry.h"

namespace {

namespace fs = std::filesystem;

using CliResult = cradle::test::RunResult;

// Runs cradle in `dir` (illustrate writes models/ under the working folder).
CliResult cradle_in(const fs::path& dir, const std::string& args) {
  return cradle::test::run_cradle(args, dir);
}

int lines(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

TEST(Illustrate, BadFlagsAreOneLineErrors) {
  const fs::path dir = fs::temp_directory_path();
  for (const char* args :
       {"--env reach --algorithm HER", "--env fly --algorithm PPO", "--env reach --algorithm XYZ",
        "--env reach --algorithm PPO --load_model /no/such.ckpt",
        "--env reach --algorithm PPO --save_every 0", "--env reach --algorithm PPO --palm_up",
        "--env standup --algorithm PPO --jitter", "--env reach --train_for 10",
        "--env reach --algorithm PPO --teacher Random"}) {
    const CliResult r = cradle_in(dir, std::string("illustrate ") + args);
    EXPECT_EQ(r.status, 1) << args;
    EXPECT_EQ(lines(r.out), 1) << args << ": " << r.out;
  }
  EXPECT_NE(cradle_in(dir, "illustrate --env reach --algorithm HER").out.find("not supported"),
            std::string::npos);
  // The algorithms are the learner registry's, named in any case.
  const std::string unknown = cradle_in(dir, "illustrate --env reach --algorithm XYZ").out;
  EXPECT_NE(unknown.find(cradle::learn::algorithm_list()), std::string::npos) << unknown;
  EXPECT_EQ(cradle_in(dir, "illustrate --env reach --algorithm SaCCM --test_for 0").status, 0);
}

TEST(Illustrate, TrainsSavesTestsFilmsAndReloads) {
  const fs::path dir =
      fs::temp_directory_path() / ("cradle_illustrate_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  CliResult r = cradle_in(dir,
                          "illustrate --env reach --algorithm PPO --train_for 64 --test_for 12 "
                          "--save_every 32 --save_model tiny --hp n_steps=32 --hp batch_size=32 "
                          "--render_video");
  ASSERT_EQ(r.status, 0) << r.out;
  const fs::path models = dir / "models" / "reach" / "tiny";
  EXPECT_TRUE(fs::exists(models / "model_1.ckpt"));
  EXPECT_TRUE(fs::exists(models / "model_2.ckpt"));
  EXPECT_FALSE(fs::exists(models / "model_3.ckpt"));
  // The run's progress rows carry the training success rate (the env's "is_success").
  std::ifstream progress(models / "logs" / "progress.csv");
  std::string header;
  ASSERT_TRUE(std::getline(progress, header));
  EXPECT_NE(header.find("behaviour/score,charts/success_rate,losses/"), std::string::npos)
      << header;
  EXPECT_FALSE(fs::exists(models / "progress.csv"));
  // The models are the run's step checkpoints under the reference's names (train::train's run).
  EXPECT_TRUE(fs::equivalent(models / "model_1.ckpt", models / "checkpoints" / "step_32.ckpt"));
  EXPECT_TRUE(fs::equivalent(models / "model_2.ckpt", models / "checkpoints" / "step_64.ckpt"));
  // Curves are drawn even when no training episode ended yet (reach lasts 1000 steps).
  EXPECT_GT(fs::file_size(models / "plots" / "learning_curve_return.png"), 0u);
  EXPECT_GT(fs::file_size(models / "plots" / "learning_curve_success.png"), 0u);
  EXPECT_GT(fs::file_size(models / "episode_0.mp4"), 0u);
  EXPECT_NE(r.out.find("success rate"), std::string::npos) << r.out;

  r = cradle_in(dir,
                "illustrate --env reach --algorithm PPO --test_for 5 --save_model tiny "
                "--load_model " +
                    (models / "model_2.ckpt").string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("the trained policy"), std::string::npos) << r.out;
  // Without --algorithm the checkpoint's algorithm is taken.
  r = cradle_in(dir, "illustrate --env reach --test_for 5 --save_model tiny --load_model " +
                         (models / "model_2.ckpt").string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("the trained policy"), std::string::npos) << r.out;
  // Another algorithm's model is refused.
  r = cradle_in(dir, "illustrate --env reach --algorithm A2C --test_for 5 --load_model " +
                         (models / "model_2.ckpt").string());
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(lines(r.out), 1) << r.out;
  // Training again under the same name is refused (the models stay) unless --overwrite.
  const auto model = [&] {
    std::ifstream in(models / "model_2.ckpt", std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  };
  const std::string before = model();
  const std::string again =
      "illustrate --env reach --algorithm PPO --train_for 32 --test_for 0 --save_every 32 "
      "--save_model tiny --hp n_steps=32 --hp batch_size=32 --seed 9";
  r = cradle_in(dir, again);
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_EQ(lines(r.out), 1) << r.out;
  EXPECT_NE(r.out.find("give --overwrite"), std::string::npos) << r.out;
  EXPECT_EQ(model(), before);
  r = cradle_in(dir, again + " --overwrite");
  ASSERT_EQ(r.status, 0) << r.out;
  // Retraining the folder's own model over it: the model is read before the folder is cleared.
  r = cradle_in(dir, again + " --overwrite --load_model " + (models / "model_1.ckpt").string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("trained 32 steps"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(models / "model_1.ckpt"));
  EXPECT_FALSE(fs::exists(models / "model_2.ckpt"));  // the earlier run's models went
  fs::remove_all(dir);
}

// A curriculum on catch (the shipped file): the teacher's throws reach the training envs and every
// training episode is booked with its task inside the file's box.
TEST(Illustrate, CatchCurriculumBooksEveryTrainingEpisode) {
  const fs::path dir = cradle::test::fresh_dir("illustrate_curriculum");
  const std::string file = std::string(CRADLE_SOURCE_DIR) + "/configs/curricula/mimo_catch.yml";
  const CliResult r = cradle_in(dir,
                                "illustrate --env catch --algorithm PPO --train_for 256 "
                                "--test_for 0 --save_model cur --hp n_steps=128 --hp batch_size=64 "
                                "--task-space " +
                                    file);
  ASSERT_EQ(r.status, 0) << r.out;
  std::ifstream book(dir / "models" / "catch" / "cur" / "logs" / "teacher.jsonl");
  int train = 0, dumps = 0;
  for (std::string line; std::getline(book, line);) {
    const nlohmann::json j = nlohmann::json::parse(line);
    if (j["kind"] == "train") {
      ++train;
      const auto task = j["task"].get<std::vector<double>>();
      ASSERT_EQ(task.size(), 3u);
      EXPECT_GE(task[1], 0.0);  // ball_speed in [0, 2]
      EXPECT_LE(task[1], 2.0);
    } else {
      EXPECT_EQ(j["teacher"]["teacher"], "alp_gmm");  // the file's teacher
      ++dumps;
    }
  }
  EXPECT_GT(train, 2);  // a dropped ball ends an episode within a few dozen steps
  EXPECT_EQ(dumps, 1);
}

// The reference's documented call without --algorithm and without a model tests random actions,
// the same (seeded) episodes as with an algorithm named but no model.
TEST(Illustrate, NoAlgorithmAndNoModelTestsRandomActions) {
  const fs::path dir = cradle::test::fresh_dir("illustrate_random");
  const CliResult r = cradle_in(dir, "illustrate --env catch --test_for 200 --seed 4");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("with random actions"), std::string::npos) << r.out;
  const CliResult named = cradle_in(dir,
                                    "illustrate --env catch --test_for 200 --seed 4 "
                                    "--algorithm SAC");
  ASSERT_EQ(named.status, 0) << named.out;
  EXPECT_EQ(r.out, named.out);
  EXPECT_NE(r.out.find("test episodes: success rate"), std::string::npos) << r.out;
  fs::remove_all(dir);
}

TEST(Illustrate, BenchMeasuresASampleEnv) {
  const CliResult r =
      cradle_in(fs::temp_directory_path(), "bench --json --steps 50 --env MIMoReach-v0");
  ASSERT_EQ(r.status, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["config"], "MIMoReach-v0");
  EXPECT_EQ(j["frame_skip"], 2);
  EXPECT_GT(j["env_steps_per_s"].get<double>(), 0);
  const CliResult bad = cradle_in(fs::temp_directory_path(), "bench --steps 5");
  EXPECT_EQ(bad.status, 1);
  EXPECT_EQ(lines(bad.out), 1) << bad.out;
}

}  // namespace

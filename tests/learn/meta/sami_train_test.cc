// SaMI's train / evaluate / table: a few-hundred-step run of every method on Panda push and on a
// crippled locomotion env, the same run as `cradle train`'s, resume, evaluation files and the
// table.
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "core/error.h"
#include "learn/checkpoint.h"
#include "learn/meta/samplers.h"
#include "train/sami/sami_experiment.h"
#include "train/trainer.h"

namespace cradle::train {
namespace {

// Small networks and batches so that a run takes a fraction of a second.
std::map<std::string, std::string> tiny_hp() {
  return {{"net_arch", "32,32"},        {"lstm_hidden", "16"},     {"batch_size", "4"},
          {"contrast_batch_size", "4"}, {"buffer_size", "8"},      {"train_freq", "10"},
          {"gradient_steps", "2"},      {"learning_starts", "60"}, {"adversarial_loss_coef", "1"}};
}

std::filesystem::path scratch(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("cradle_sami_" + name);
  std::filesystem::remove_all(dir);
  return dir;
}

int lines(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string line;
  int n = 0;
  while (std::getline(in, line)) ++n;
  return n;
}

TEST(SamiTrain, EveryMethodRunsOnPandaAndACrippledEnv) {
  for (const std::string env : {"PandaPush", "CrippleHalfCheetah"}) {
    for (const std::string_view method : learn::meta::method_names()) {
      const auto dir = scratch(env + std::string(method));
      auto hp = tiny_hp();
      if (env != "PandaPush") {  // train after the first 1000-step episodes, 3 updates
        hp["learning_starts"] = "1000";
        hp["train_freq"] = "20";
        hp["gradient_steps"] = "1";
      }
      const SamiTrainResult r = sami_train({.env = env,
                                            .method = std::string(method),
                                            .seed = 1,
                                            .steps_per_env = env == "PandaPush" ? 200 : 1040,
                                            .hyperparameters = hp,
                                            .out = dir,
                                            .progress_bar = false});
      const int envs = env == "PandaPush" ? 6 : 3;  // CrippleHalfCheetah: one set per joint
      EXPECT_EQ(r.steps, (env == "PandaPush" ? 200 : 1040) * envs) << env << method;
      EXPECT_GT(r.updates, 0) << env << method;
      EXPECT_TRUE(std::filesystem::exists(dir / "checkpoints" / "final.ckpt"));
      EXPECT_EQ(r.checkpoint, dir / "checkpoints" / "final.ckpt");
      EXPECT_GE(lines(dir / "logs" / "progress.csv"), 2);
      std::filesystem::remove_all(dir);
    }
  }
}

std::string bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// `sami train` is `cradle train --env sami/<Env> --algo <learner>` with SaMI's settings: one env
// per training set on one thread, no intrinsic reward, the env's horizon; both runs end with the
// same checkpoint bytes.
TEST(SamiTrain, IsCradleTrainWithSamisSettings) {
  const auto dir = scratch("front");
  auto hp = tiny_hp();
  const SamiTrainResult r = sami_train({.env = "PandaPush",
                                        .method = "SaTESAC",
                                        .seed = 6,
                                        .steps_per_env = 120,
                                        .hyperparameters = hp,
                                        .out = dir / "sami",
                                        .progress_bar = false});
  EXPECT_EQ(r.steps, 720);
  Config config;
  config.save_dir = (dir / "train").string();
  // SaMI's horizon, progress rows and Panda's sizes come with cradle train's presets.
  const TrainResult t = train(config, {.env = "sami/PandaPush",
                                       .algorithm = "satesac",
                                       .intrinsic = "",
                                       .steps = 720,
                                       .envs = 6,
                                       .threads = 1,
                                       .seed = 6,
                                       .hyperparameters = hp,
                                       .eval_episodes = 0,
                                       .progress_bar = false});
  EXPECT_EQ(t.steps, 720);
  EXPECT_EQ(learn::read_checkpoint_info(r.checkpoint).config,
            learn::read_checkpoint_info(t.checkpoint).config);
  EXPECT_EQ(bytes(r.checkpoint), bytes(t.checkpoint));
  // Panda's 50-step episodes as trajectories and progress rows; the tiny sizes given win.
  const std::string settings = learn::read_checkpoint_info(t.checkpoint).config;
  for (const char* line : {"horizon = 50\n", "report_every = 50\n", "batch_size = 4\n"})
    EXPECT_NE(settings.find(line), std::string::npos) << line << settings;
  std::filesystem::remove_all(dir);
}

TEST(SamiTrain, ResumeContinuesAndEvaluateWritesCells) {
  const auto dir = scratch("resume");
  SamiTrainOptions o{.env = "PandaPush",
                     .method = "SaCCM",
                     .seed = 2,
                     .steps_per_env = 100,
                     .hyperparameters = tiny_hp(),
                     .out = dir,
                     .report_every = 25,
                     .progress_bar = false};
  sami_train(o);
  EXPECT_THROW(sami_train(o), UserError);  // the folder holds a run: --resume or another --out
  o.resume = true;
  o.steps_per_env = 200;
  const SamiTrainResult r = sami_train(o);
  EXPECT_EQ(r.steps, 1200);
  // header + one row per 25 vector steps
  EXPECT_EQ(lines(dir / "logs" / "progress.csv"), 1 + 200 / 25);

  const SamiEvalResult e = sami_evaluate({.run = dir, .split = "extreme", .episodes = 1});
  ASSERT_EQ(e.cells.size(), 8u);  // Panda's 8 extreme cells
  EXPECT_TRUE(e.skills);
  for (const SamiCell& c : e.cells) {
    EXPECT_NEAR(c.push + c.roll + c.pick_and_place, 1.0, 1e-9) << c.name;  // one label each
  }
  // A row per step: 50 per episode unless it succeeded earlier.
  EXPECT_GT(lines(e.contexts), 1 + 8);
  EXPECT_LE(lines(e.contexts), 1 + 8 * 50);
  std::ifstream json(e.json);
  const auto j = nlohmann::json::parse(json);
  EXPECT_EQ(j.at("method"), "SaCCM");
  EXPECT_EQ(j.at("cells").size(), 8u);
  EXPECT_THROW(sami_evaluate({.run = dir, .split = "hard"}), UserError);
  // The evaluations measured this run: a folder holding only them is refused, and --overwrite
  // removes them with the run.
  std::filesystem::remove_all(dir / "checkpoints");
  std::filesystem::remove_all(dir / "logs");
  o.resume = false;
  o.steps_per_env = 25;
  try {
    sami_train(o);
    ADD_FAILURE() << "a folder holding evaluations was not refused";
  } catch (const UserError& error) {
    EXPECT_NE(std::string(error.what()).find("holds a run"), std::string::npos) << error.what();
  }
  EXPECT_TRUE(std::filesystem::exists(e.json));
  o.overwrite = true;
  sami_train(o);
  for (const auto& file : {e.json, e.csv, e.contexts}) EXPECT_FALSE(std::filesystem::exists(file));
  std::filesystem::remove_all(dir);
}

// The context rows of a crippled env name the parameters each episode drew: a mass of its task
// set, damping 1 and two of the six joints (the extreme split of CrippleHalfCheetah).
TEST(SamiEvaluate, ContextRowsNameTheDrawnTask) {
  const auto dir = scratch("contexts");
  auto hp = tiny_hp();
  hp["learning_starts"] = "1000";
  sami_train({.env = "CrippleHalfCheetah",
              .method = "CCM",
              .seed = 4,
              .steps_per_env = 10,
              .hyperparameters = hp,
              .out = dir,
              .progress_bar = false});
  const SamiEvalResult e = sami_evaluate({.run = dir, .split = "extreme", .episodes = 2});
  EXPECT_FALSE(e.skills);  // locomotion: no success or skill columns to print
  std::ifstream in(e.contexts);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(
      line.rfind("task_set,cell,episode,step,mass,damping,crippled,skill,episode_skill,c0,", 0), 0u)
      << line;
  int rows = 0;
  while (std::getline(in, line)) {
    // The fields after the quoted cell name: episode, step, mass, damping, crippled, ...
    std::stringstream fields(line.substr(line.rfind('"') + 2));
    std::string episode, step, mass, damping, crippled;
    std::getline(fields, episode, ',');
    std::getline(fields, step, ',');
    std::getline(fields, mass, ',');
    std::getline(fields, damping, ',');
    std::getline(fields, crippled, ',');
    EXPECT_EQ(std::stoi(step) % 10, 0);  // every 10th step on locomotion
    const double m = std::stod(mass);
    EXPECT_TRUE(m == 0.2 || m == 0.3 || m == 1.7 || m == 1.8) << line;
    EXPECT_EQ(damping, "1");
    ASSERT_EQ(crippled.size(), 3u) << line;  // two joints ascending, e.g. "1+4" or "4+5"
    EXPECT_GE(crippled[0], '0');
    EXPECT_EQ(crippled[1], '+');
    EXPECT_LT(crippled[0], crippled[2]);
    EXPECT_LE(crippled[2], '5');
    ++rows;
  }
  EXPECT_EQ(rows, 2 * 2 * 1000 / 10);  // 2 task sets x 2 episodes x 100 rows
  std::filesystem::remove_all(dir);
}

// A stop request (Ctrl-C, here before the first step) ends the run with a checkpoint; --resume
// continues from it to the budget.
TEST(SamiTrain, StopWritesACheckpointThatResumes) {
  const auto dir = scratch("stop");
  std::atomic<bool> stop{true};
  SamiTrainOptions o{.env = "PandaPush",
                     .method = "CCM",
                     .seed = 3,
                     .steps_per_env = 100,
                     .hyperparameters = tiny_hp(),
                     .out = dir,
                     .checkpoint_every = 1000,
                     .report_every = 25,
                     .progress_bar = false,
                     .stop = &stop};
  const SamiTrainResult stopped = sami_train(o);
  EXPECT_TRUE(stopped.stopped);
  EXPECT_EQ(stopped.steps, 0);
  EXPECT_TRUE(std::filesystem::exists(dir / "checkpoints" / "latest.ckpt"));
  EXPECT_EQ(lines(dir / "logs" / "progress.csv"), 1);  // the header
  stop = false;
  o.resume = true;
  const SamiTrainResult r = sami_train(o);
  EXPECT_FALSE(r.stopped);
  EXPECT_EQ(r.steps, 600);
  EXPECT_EQ(lines(dir / "logs" / "progress.csv"), 1 + 100 / 25);
  std::filesystem::remove_all(dir);
}

TEST(SamiTable, MeansStdsAndWelchPerSplit) {
  const auto root = scratch("table");
  const double train_scores[2][3] = {{0.9, 0.95, 0.92}, {0.5, 0.6, 0.55}};
  std::vector<std::filesystem::path> runs;
  for (int m = 0; m < 2; ++m) {
    for (int s = 0; s < 3; ++s) {
      const auto run = root / (std::to_string(m) + "_" + std::to_string(s));
      std::filesystem::create_directories(run);
      std::ofstream(run / "eval_train.json") << nlohmann::json{
          {"env", "PandaPush"},
          {"method", m ? "CCM" : "SaCCM"},
          {"success_rate", train_scores[m][s]},
          {"mean_return", -10}}.dump();
      runs.push_back(run);
    }
  }
  const std::string table = sami_table(runs);
  EXPECT_NE(table.find("| SaCCM | 3 | 0.92 ± 0.03 | – | – |"), std::string::npos) << table;
  EXPECT_NE(table.find("| CCM | 3 | 0.55 ± 0.05 | – | – |"), std::string::npos) << table;
  const Welch w = welch_test({0.9, 0.95, 0.92}, {0.5, 0.6, 0.55});
  char expected[64];
  std::snprintf(expected, sizeof(expected), "t = %.2f, p = %.4f", w.t, w.p);
  EXPECT_NE(table.find(std::string("| SaCCM vs CCM | ") + expected), std::string::npos) << table;
  EXPECT_THROW(sami_table({root / "missing"}), UserError);
  std::filesystem::remove_all(root);
}

TEST(SamiTrain, BadInputsAreOneLineErrors) {
  EXPECT_THROW(sami_train({.env = "Nope", .out = scratch("bad")}), UserError);
  EXPECT_THROW(sami_train({.env = "PandaPush", .method = "SaCCM2", .out = scratch("bad")}),
               UserError);
  EXPECT_THROW(
      sami_train(
          {.env = "PandaPush", .hyperparameters = {{"neg_ratio", "2"}}, .out = scratch("bad")}),
      UserError);
  // CCM contrasts envs: CrippleHopper's single training set splits into one env per mass value.
  EXPECT_EQ(sami_training_sets(sami::EnvId::kCrippleHopper).size(), 5u);
  EXPECT_EQ(sami_training_sets(sami::EnvId::kCrippleHalfCheetah).size(), 3u);
  EXPECT_EQ(sami_training_sets(sami::EnvId::kPandaPush).size(), 6u);
  std::filesystem::remove_all(scratch("bad"));
}

}  // namespace
}  // namespace cradle::train

// Every registered env id trains through the one run (train::train): a few hundred PPO steps on
// each, a learner of each kind on each family, and a teacher over SaMI's hidden parameters whose
// tasks reach the envs.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "core/config.h"
#include "core/error.h"
#include "envs/registry.h"
#include "envs/sami/sami_env.h"
#include "fixture.h"
#include "learn/learner.h"
#include "learn/vector_env.h"
#include "train/env_vector.h"
#include "train/trainer.h"

namespace cradle::test {
namespace {

namespace fs = std::filesystem;

// Rows of progress.csv after the header.
int progress_rows(const fs::path& csv) {
  std::ifstream in(csv);
  std::string line;
  int rows = -1;
  while (std::getline(in, line)) ++rows;
  return rows;
}

// A short run of `algo` on env `id`: a BabyBench id as its config, any other by id.
train::TrainResult short_run(const std::string& id, const std::string& algo, long steps,
                             const fs::path& dir,
                             std::map<std::string, std::string> hp = {
                                 {"n_steps", "32"}, {"batch_size", "32"}, {"n_epochs", "1"}}) {
  const envs::EnvSpec spec = envs::env_spec(id);
  Config config;
  train::TrainOptions o{.algorithm = algo, .intrinsic = "", .steps = steps, .envs = 2};
  if (spec.family == "babybench") {
    if (!spec.config.empty()) config = load_config(spec.config);
    config.max_episode_steps = 40;
  } else {
    o.env = spec.id;
  }
  config.save_dir = dir.string();
  o.threads = 2;
  o.checkpoint_every = steps;
  o.eval_episodes = 0;
  o.progress_bar = false;
  o.hyperparameters = std::move(hp);
  return train::train(config, o);
}

TEST(EnvMatrix, EveryRegisteredIdTrainsAFewHundredStepsOfPpo) {
  const fs::path root = fresh_dir("env_matrix");
  int trained = 0;
  for (const envs::EnvSpec& spec : envs::env_specs()) {
    SCOPED_TRACE(spec.id);
    // The one-minute benchmark scenes (two 256x256 eyes each) are covered by their family's
    // other ids; every other id runs here.
    if (spec.id == "mimo/bench" || spec.id == "mimo/bench-v2" || spec.id == "mimo/showroom")
      continue;
    const fs::path dir = root / std::to_string(trained);
    const train::TrainResult r = short_run(spec.id, "ppo", 128, dir);
    EXPECT_EQ(r.steps, 128);
    EXPECT_TRUE(fs::exists(dir / "checkpoints" / "final.ckpt"));
    EXPECT_EQ(progress_rows(dir / "logs" / "progress.csv"), 2);  // one row per 64-step rollout
    ++trained;
  }
  EXPECT_GE(trained, 60);
  fs::remove_all(root);
}

// One learner of each kind on each non-BabyBench family (BabyBench's configs have their own).
TEST(EnvMatrix, OffPolicyLearnersTrainOnEveryFamily) {
  const fs::path root = fresh_dir("env_matrix_off_policy");
  const std::map<std::string, std::string> off = {{"learning_starts", "32"},
                                                  {"batch_size", "16"},
                                                  {"report_every", "32"},
                                                  {"pi_layers", "32,32"},
                                                  {"qf_layers", "32,32"}};
  const std::vector<std::pair<std::string, std::string>> runs = {
      {"mimo/reach", "sac"}, {"tma/parkour:fish", "td3"}, {"sami/CrippleAnt:moderate", "ddpg"}};
  for (const auto& [id, algo] : runs) {
    SCOPED_TRACE(id + " " + algo);
    const train::TrainResult r = short_run(id, algo, 128, root / algo, off);
    EXPECT_EQ(r.steps, 128);
    EXPECT_TRUE(fs::exists(root / algo / "checkpoints" / "final.ckpt"));
  }
  fs::remove_all(root);
}

// SaMI's context learners train through the same run: SaCCM on SaMI's own training sets (one per
// env) and, across families, TESAC on a MIMo sample task.
TEST(EnvMatrix, SamiLearnersTrainOnSamiAndOnOtherFamilies) {
  const fs::path root = fresh_dir("env_matrix_sami_learners");
  const std::map<std::string, std::string> hp = {
      {"learning_starts", "100"}, {"train_freq", "50"},         {"gradient_steps", "1"},
      {"batch_size", "2"},        {"contrast_batch_size", "2"}, {"net_arch", "32,32"},
      {"lstm_hidden", "16"},      {"horizon", "100"},           {"report_every", "100"}};
  for (const auto& [id, algo] : std::vector<std::pair<std::string, std::string>>{
           {"sami/CrippleHalfCheetah", "saccm"}, {"mimo/reach", "tesac"}}) {
    SCOPED_TRACE(id + " " + algo);
    const fs::path dir = root / algo;
    const train::TrainResult r = short_run(id, algo, 400, dir, hp);
    EXPECT_EQ(r.steps, 400);
    EXPECT_TRUE(fs::exists(dir / "checkpoints" / "final.ckpt"));
    EXPECT_EQ(learn::read_checkpoint_info(dir / "checkpoints" / "final.ckpt").algorithm, algo);
    // progress.csv: the common columns, then the learner's own (SaNCE's loss and weight), filled
    // once updates run.
    std::ifstream csv(dir / "logs" / "progress.csv");
    std::string header, row, last;
    std::getline(csv, header);
    EXPECT_TRUE(header.ends_with(",perf/update_seconds,losses/sance_loss,losses/sance_weight"))
        << header;
    while (std::getline(csv, row)) last = row;
    ASSERT_FALSE(last.empty());
    EXPECT_NE(last.back(), ',') << last;  // the weight of the last report's updates
  }
  fs::remove_all(root);
}

// A teacher over SaMI's hidden parameters: ALP-GMM picks mass and damping for every episode and
// the env runs with them (a curriculum meta-RL run the reference does not offer).
// An env whose info says "is_success" gets charts/success_rate: each row's rate is the successes
// over the episodes that ended since the last row (empty when none ended); BabyBench's has none.
TEST(EnvMatrix, ProgressRowsCarryTheSuccessRateOfTheEpisodesEndedSinceTheLast) {
  const fs::path dir = fresh_dir("env_matrix_success");
  Config config;
  config.save_dir = dir.string();
  train::TrainOptions o{.env = "tma/stump-tracks:old_classic_bipedal",
                        .algorithm = "ppo",
                        .intrinsic = "",
                        .steps = 1024,
                        .envs = 2};
  o.threads = 2;
  o.checkpoint_every = 1024;
  o.eval_episodes = 0;
  o.progress_bar = false;
  o.hyperparameters = {{"n_steps", "64"}, {"batch_size", "64"}, {"n_epochs", "1"}};
  // The test's own tally of the ended episodes (a walker that falls ends its episode).
  long ended = 0, successes = 0;
  std::vector<std::pair<long, long>> per_row;
  o.reward_hook = [&](const learn::VecEnv& env, std::span<const double>, std::span<double>) {
    const int slot = env.info(0).find("is_success");
    for (int i = 0; i < env.num_envs(); ++i) {
      if (env.terminated()[i] || env.truncated()[i]) {
        ++ended;
        successes += env.info(i).flag(slot);
      }
    }
  };
  o.on_report = [&](const learn::TrainStats&) {
    per_row.emplace_back(successes, ended);
    successes = ended = 0;
  };
  train::train(config, o);
  std::ifstream in(dir / "logs" / "progress.csv");
  std::string line;
  ASSERT_TRUE(std::getline(in, line));
  EXPECT_NE(line.find(",behaviour/score,charts/success_rate,losses/value_loss,"),
            std::string::npos);
  long total = 0;
  for (const auto& [s, e] : per_row) {
    ASSERT_TRUE(std::getline(in, line));
    std::vector<std::string> cells;
    std::stringstream row(line);
    for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
    ASSERT_GT(cells.size(), 6u);
    if (e == 0) {
      EXPECT_EQ(cells[6], "");
    } else {
      EXPECT_DOUBLE_EQ(std::stod(cells[6]), static_cast<double>(s) / static_cast<double>(e));
    }
    total += e;
  }
  EXPECT_EQ(per_row.size(), 8u);
  EXPECT_GT(total, 0);  // random walkers fall within 1,024 steps
  // A BabyBench config's rows have no such column.
  const fs::path babybench = dir / "babybench";
  short_run("babybench/selftouch", "ppo", 64, babybench);
  std::ifstream bb(babybench / "logs" / "progress.csv");
  ASSERT_TRUE(std::getline(bb, line));
  EXPECT_EQ(line.find("success_rate"), std::string::npos) << line;
  fs::remove_all(dir);
}

TEST(EnvMatrix, AlpGmmDrivesSamiMassAndDamping) {
  const fs::path dir = fresh_dir("env_matrix_sami_curriculum");
  Config config;
  config.save_dir = dir.string();
  train::TrainOptions o{
      .env = "sami/HalfCheetah", .algorithm = "ppo", .intrinsic = "", .steps = 4096, .envs = 2};
  o.threads = 2;
  o.eval_episodes = 0;
  o.progress_bar = false;
  o.hyperparameters = {{"n_steps", "256"}, {"batch_size", "128"}, {"n_epochs", "1"}};
  o.task_space = std::string(CRADLE_SOURCE_DIR) + "/configs/curricula/sami_mass_damping.yml";
  train::train(config, o);
  // Four 1000-step episodes ended; each trained on a task inside the file's box.
  std::ifstream in(dir / "logs" / "teacher.jsonl");
  int episodes = 0;
  for (std::string line; std::getline(in, line);) {
    const nlohmann::json e = nlohmann::json::parse(line);
    if (e["kind"] != "train") continue;
    ++episodes;
    for (double v : e["task"]) {
      EXPECT_GE(v, 0.2);
      EXPECT_LE(v, 1.8);
    }
    EXPECT_EQ(e["length"], 1000);
  }
  EXPECT_EQ(episodes, 4);
  fs::remove_all(dir);
}

// The hidden parameters a teacher sets are the ones the next episode runs with; out-of-range
// or unknown ones are refused before anything changes.
TEST(EnvMatrix, SamiResetOptionsSetTheHiddenParameters) {
  std::unique_ptr<envs::Env> env = envs::make_env("sami/HalfCheetah:extreme", 3);
  auto& sami = dynamic_cast<envs::SamiEnvAdapter&>(*env);
  env->set_reset_options({{"mass", 1.37}, {"damping", 0.61}});
  for (int episode = 0; episode < 3; ++episode) {
    env->reset();
    EXPECT_DOUBLE_EQ(sami.sami().info().mass, 1.37);
    EXPECT_DOUBLE_EQ(sami.sami().info().damping, 0.61);
  }
  EXPECT_THROW(env->set_reset_options({{"mass", 9.0}}), UserError);
  EXPECT_THROW(env->set_reset_options({{"cube_mass", 1.0}}), UserError);
  env->reset();
  EXPECT_DOUBLE_EQ(sami.sami().info().mass, 1.37);  // the refused options changed nothing
  // Panda's (friction, cube mass) cell.
  std::unique_ptr<envs::Env> panda = envs::make_env("sami/PandaPush", 3);
  panda->set_reset_options({{"table_friction", 2.5}, {"cube_mass", 7.0}});
  panda->reset();
  EXPECT_DOUBLE_EQ(dynamic_cast<envs::SamiEnvAdapter&>(*panda).sami().info().friction, 2.5);
  EXPECT_DOUBLE_EQ(dynamic_cast<envs::SamiEnvAdapter&>(*panda).sami().info().mass, 7.0);
}

// An id's parts, as every family's maker and the run read them.
TEST(EnvMatrix, AnIdSplitsIntoFamilyNameAndVariant) {
  const envs::EnvIdParts fish = envs::split_env_id("tma/parkour:fish");
  EXPECT_EQ(fish.family, "tma");
  EXPECT_EQ(fish.name, "parkour");
  EXPECT_EQ(fish.variant, "fish");
  const envs::EnvIdParts reach = envs::split_env_id("mimo/reach");
  EXPECT_EQ(reach.family, "mimo");
  EXPECT_EQ(reach.name, "reach");
  EXPECT_EQ(reach.variant, "");
  const envs::EnvIdParts none = envs::split_env_id("reach");
  EXPECT_EQ(none.family + none.name + none.variant, "");
}

TEST(EnvMatrix, AnUnknownIdNamesTheClosestOnes) {
  try {
    envs::env_spec("sami/CripleAnt");
    FAIL() << "expected a UserError";
  } catch (const UserError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("sami/CrippleAnt"), std::string::npos) << m;
    EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  }
  EXPECT_EQ(envs::env_spec("MIMoReach-v0").id, "mimo/reach");
  EXPECT_EQ(envs::env_spec("sami/CrippleAnt").id, "sami/CrippleAnt:train");
  EXPECT_EQ(envs::env_spec("BabyBench-SelfTouch").id, "babybench/selftouch");
  EXPECT_EQ(train::registered_env_id("reach"), "mimo/reach");
  EXPECT_THROW(envs::env_spec("tma/parkour:nobody"), UserError);
  EXPECT_THROW(envs::env_maker("mimo/reach", {{"actuation", "jelly"}}), UserError);
  EXPECT_THROW(envs::env_maker("tma/parkour:fish", {{"nb_of_bodies", "4"}}), UserError);
}

// SaMI vectors hold one training task set per env, as SaMI's DummyVecEnv: env i draws from set
// i mod the number of sets; a lone env draws from every set.
TEST(EnvMatrix, SamiVectorEnvsEachHoldOneTaskSet) {
  const envs::EnvSpec spec = envs::env_spec("sami/CrippleHalfCheetah");
  ASSERT_EQ(spec.natural_envs, 3);
  const envs::EnvMaker make = envs::env_maker(spec.id);
  auto sets = [&](int index) {
    auto env = make(index, 11);
    return dynamic_cast<envs::SamiEnvAdapter&>(*env).sami().task_sets();
  };
  for (int i = 0; i < 4; ++i) {
    ASSERT_EQ(sets(i).size(), 1u);
    EXPECT_EQ(sets(i)[0].cripple.size(), 1u);  // one crippling choice each
  }
  EXPECT_NE(sets(0)[0].cripple, sets(1)[0].cripple);
  EXPECT_EQ(sets(0)[0].cripple, sets(3)[0].cripple);
  // A lone env draws from the split's one set of every choice.
  EXPECT_EQ(sets(-1).size(), 1u);
  EXPECT_EQ(sets(-1)[0].cripple.size(), 3u);
}

}  // namespace
}  // namespace cradle::test

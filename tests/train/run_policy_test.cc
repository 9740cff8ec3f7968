// A run's trained policy by its folder (train/run_policy.h): it acts as the run's own evaluation
// did, and a damaged run folder is one line naming the file, the key and what was expected.
#include "train/run_policy.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/error.h"
#include "envs/registry.h"
#include "fixture.h"
#include "train/trainer.h"

namespace cradle::train {
namespace {

namespace fs = std::filesystem;

const char* const kEnv = "tma/stump-tracks:old_classic_bipedal";

// A tiny PPO run by id in `dir`; its result holds the run's own evaluation episodes.
TrainResult tiny_run(const fs::path& dir) {
  Config config;
  config.save_dir = dir.string();
  TrainOptions o{.env = kEnv, .algorithm = "ppo", .intrinsic = "", .steps = 256, .envs = 2};
  o.seed = 4;
  o.progress_bar = false;
  o.hyperparameters = {{"n_steps", "64"}, {"batch_size", "64"}, {"n_epochs", "1"}};
  return train(config, o);
}

// The message of the UserError `f` throws ("" when it throws none).
template <typename F>
std::string user_error(F&& f) {
  try {
    f();
  } catch (const UserError& e) {
    return e.what();
  }
  return "";
}

TEST(RunPolicy, ActsAsTheRunsOwnEvaluation) {
  const fs::path dir = test::fresh_dir("run_policy_acts");
  const TrainResult trained = tiny_run(dir / "run");
  ASSERT_EQ(trained.episodes.size(), 2u);
  const RunPolicy policy = load_run_policy(dir / "run");
  EXPECT_EQ(policy.run().env, kEnv);
  EXPECT_EQ(policy.run().family, "tma");
  EXPECT_EQ(policy.run().algorithm, "ppo");
  EXPECT_EQ(policy.run().seed, 4u);
  EXPECT_EQ(policy.checkpoint_name(), "final");
  EXPECT_EQ(policy.steps(), 256);
  EXPECT_FALSE(policy.sampled());
  auto env = envs::make_env(kEnv, 1004);
  const std::vector<std::uint64_t> seeds = {1004, 1005};
  const std::vector<EpisodeOutcome> again = run_episodes(*env, policy.episode_policy(), seeds);
  for (size_t e = 0; e < seeds.size(); ++e) {
    EXPECT_EQ(again[e].seed, trained.episodes[e].seed);
    EXPECT_EQ(again[e].episode_return, trained.episodes[e].episode_return);
    EXPECT_EQ(again[e].length, trained.episodes[e].length);
  }
  // Sampled actions come from the checkpoint's generator: a fresh load repeats them.
  auto sampled_return = [&] {
    const RunPolicy sampled = load_run_policy(dir / "run", "latest", /*sampled=*/true);
    return run_episodes(*env, sampled.episode_policy(), seeds).front().episode_return;
  };
  EXPECT_EQ(sampled_return(), sampled_return());
  fs::remove_all(dir);
}

TEST(RunPolicy, ADamagedRunFolderIsOneLineNamingTheFileAndKey) {
  const fs::path dir = test::fresh_dir("run_policy_damaged");
  tiny_run(dir / "run");
  const fs::path run_json = dir / "run" / "run.json";
  const nlohmann::json good = nlohmann::json::parse(std::ifstream(run_json));
  auto with = [&](const std::string& key, const nlohmann::json& value) {
    nlohmann::json j = good;
    if (value.is_null()) {
      j.erase(key);
    } else {
      j[key] = value;
    }
    std::ofstream(run_json, std::ios::trunc) << j.dump();
    return user_error([&] { load_run_policy(dir / "run"); });
  };
  EXPECT_NE(with("algorithm", nullptr).find("has no key \"algorithm\"; expected a string"),
            std::string::npos);
  EXPECT_NE(with("seed", "zero").find("\"seed\" is \"zero\"; expected an integer"),
            std::string::npos);
  EXPECT_NE(with("hyperparameters", 3).find("\"hyperparameters\" is 3; expected an object"),
            std::string::npos);
  EXPECT_NE(with("family", "mimo").find("expected \"tma\""), std::string::npos);
  EXPECT_NE(with("env", "tma/stump-trax").find("closest"), std::string::npos);
  EXPECT_NE(with("algorithm", "sac").find("holds a ppo learner"), std::string::npos);
  for (const std::string& message : {with("algorithm", nullptr), with("env", "tma/stump-trax")}) {
    EXPECT_NE(message.find(run_json.string()), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  std::ofstream(run_json, std::ios::trunc) << "{\"env\": ";
  EXPECT_NE(user_error([&] { load_run_policy(dir / "run"); }).find("is not valid JSON"),
            std::string::npos);
  fs::remove(run_json);
  EXPECT_NE(user_error([&] { load_run_policy(dir / "run"); }).find("run.json does not exist"),
            std::string::npos);
  EXPECT_NE(user_error([&] { load_run_policy(dir / "none"); }).find("does not exist"),
            std::string::npos);
  std::ofstream(run_json) << good.dump();
  const std::string missing = user_error([&] { load_run_policy(dir / "run", "step_9"); });
  EXPECT_NE(missing.find("expected one of the run's checkpoints (final, latest)"),
            std::string::npos)
      << missing;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace cradle::train

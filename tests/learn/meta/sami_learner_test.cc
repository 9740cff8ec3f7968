// SaMI's methods as ordinary learners (learn/meta/sami_learner.h): built by name, trained on SaMI
// envs, TeachMyAgent and a MuJoCo task with next-step autoresets, checkpoints that continue
// exactly, the context of each act() call, and the one-line refusals.
#include "learn/meta/sami_learner.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "envs/sami/sami_env.h"
#include "envs/tma/tma_env.h"
#include "learn/checkpoint.h"
#include "learn/grad_tensors.h"
#include "learn/hyperparams.h"
#include "learn/meta/context_sac.h"
#include "learn/networks.h"
#include "learn/registry.h"
#include "learn/test_tasks.h"
#include "learn/vector_env.h"
#include "sami/env.h"

namespace cradle::learn::meta {
namespace {

// Small networks and batches; trajectories of at most 40 steps so that training starts early.
std::map<std::string, std::string> tiny_hp() {
  return {{"net_arch", "32,32"},        {"lstm_hidden", "8"},          {"batch_size", "2"},
          {"contrast_batch_size", "4"}, {"buffer_size", "16"},         {"train_freq", "10"},
          {"gradient_steps", "1"},      {"learning_starts", "20"},     {"horizon", "40"},
          {"report_every", "50"},       {"adversarial_loss_coef", "1"}};
}

std::unique_ptr<ThreadedVecEnv> sami_envs(int count, std::uint64_t seed) {
  std::vector<std::unique_ptr<envs::Env>> list;
  for (int i = 0; i < count; ++i)
    list.push_back(envs::make_sami_env("CrippleHalfCheetah", "train", seed + i));
  return std::make_unique<ThreadedVecEnv>(std::move(list), /*threads=*/1);
}

bool one_line(const std::string& text) { return text.find('\n') == std::string::npos; }

// The message of the UserError that `build` throws ("" when it throws none).
template <typename F>
std::string user_error(F build) {
  try {
    build();
  } catch (const UserError& e) {
    return e.what();
  }
  return "";
}

std::filesystem::path scratch(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("cradle_sami_learner_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir;
}

TEST(SamiLearner, RegistryListsAndBuildsEveryAlgorithm) {
  const std::vector<std::string> expected{"ppo",   "a2c", "sac",     "td3",   "ddpg",
                                          "tesac", "ccm", "satesac", "saccm", "saccm_all"};
  EXPECT_EQ(algorithm_names(), expected);
  auto vec = sami_envs(2, 1);
  for (const std::string_view name : sami_learner_names()) {
    const auto learner = make_learner(name, *vec, {.hyperparameters = tiny_hp()});
    EXPECT_EQ(learner->algorithm(), name);
  }
  EXPECT_EQ(sami_method("saccm_all"), "SaCCMAll");
  const std::string error = user_error([&] { make_learner("dqn", *vec, {}); });
  EXPECT_TRUE(one_line(error));
  EXPECT_NE(error.find("ppo, a2c, sac, td3, ddpg, tesac, ccm, satesac, saccm or saccm_all"),
            std::string::npos)
      << error;
}

// The run asks the registry which algorithms train data-parallel or collect asynchronously;
// SaMI's context learners train data-parallel and collect lock-step.
TEST(SamiLearner, RegistryTellsWhatEachAlgorithmCanDo) {
  EXPECT_EQ(algorithms_with(&AlgorithmTraits::data_parallel),
            "ppo, a2c, sac, td3, ddpg, tesac, ccm, satesac, saccm or saccm_all");
  EXPECT_EQ(algorithms_with(&AlgorithmTraits::async_collection, "and"), "ppo and a2c");
  EXPECT_TRUE(algorithm_traits("sac").data_parallel);
  EXPECT_FALSE(algorithm_traits("sac").async_collection);
  EXPECT_TRUE(algorithm_traits("td3").data_parallel);
  for (const std::string_view name : sami_learner_names()) {
    EXPECT_TRUE(algorithm_traits(name).data_parallel) << name;
    EXPECT_FALSE(algorithm_traits(name).async_collection) << name;
  }
  const std::string error = user_error([] { algorithm_traits("dqn"); });
  EXPECT_TRUE(one_line(error));
  EXPECT_NE(error.find("unknown algorithm 'dqn'"), std::string::npos) << error;
}

TEST(SamiLearner, SaccmTrainsOnSamiEnvsAndReportsFiniteLosses) {
  auto vec = sami_envs(2, 3);
  auto learner = make_learner("saccm", *vec, {.seed = 3, .hyperparameters = tiny_hp()});
  std::vector<TrainStats> reports;
  learner->learn(2 * 150, [&](const TrainStats& s) {
    reports.push_back(s);
    return true;
  });
  EXPECT_EQ(learner->steps(), 300);
  ASSERT_EQ(reports.size(), 3u);  // vector steps 50, 100 and 150 (the end)
  EXPECT_EQ(reports.back().steps, 300);
  const TrainStats& last = reports.back();
  for (const char* name :
       {"qf_loss", "actor_loss", "alpha", "alpha_loss", "entropy", "sance_weight"}) {
    ASSERT_TRUE(last.losses.count(name)) << name;
    EXPECT_TRUE(std::isfinite(last.losses.at(name))) << name;
  }
  if (last.losses.count("sance_loss")) {
    EXPECT_TRUE(std::isfinite(last.losses.at("sance_loss")));
  }
  EXPECT_GT(last.losses.at("updates"), 0);
  EXPECT_GT(last.sps, 0);
  // 1000-step episodes, cut into 40-step trajectories: none ended.
  EXPECT_EQ(last.episodes, 0);
  EXPECT_TRUE(std::isnan(last.episodic_return));
  EXPECT_EQ(last.losses.at("buffer_trajectories"), 2 * 3);  // 150 / 40 per slot
  // The config text rebuilds the same learner.
  EXPECT_NO_THROW(make_learner(
      "saccm", *vec, {.hyperparameters = parse_hyperparameter_text(learner->config_text())}));
  // act() keeps one stream: its actions lie in the bounds.
  std::vector<double> action(6);
  for (int t = 0; t < 3; ++t) {
    learner->act(vec->observation(0), action, t == 0);
    for (const double a : action) EXPECT_TRUE(a >= -1 && a <= 1);
  }
  EXPECT_TRUE(std::isnan(learner->value(vec->observation(0))));
  // new_episode() restarts the stream; without it the context carries over.
  std::vector<double> first(6), again(6), continued(6);
  learner->new_episode();
  learner->act(vec->observation(0), first, true);
  learner->new_episode();
  learner->act(vec->observation(0), again, true);
  learner->act(vec->observation(0), continued, true);
  EXPECT_EQ(first, again);
  EXPECT_NE(again, continued);
}

TEST(SamiLearner, SaveLoadContinuesExactlyAsTheSavedLearner) {
  const auto dir = scratch("resume");
  const auto file = dir / "saccm.ckpt";
  auto hp = tiny_hp();
  hp["report_every"] = "1000";
  // Saved mid-trajectory (70 = 40 + 30 steps per slot), after updates.
  auto vec_a = sami_envs(2, 5);
  auto a = make_learner("saccm", *vec_a, {.seed = 5, .hyperparameters = hp});
  a->learn(2 * 70, {});
  a->save(file);
  const std::uint64_t saved = a->parameter_hash();
  a->learn(2 * 130, {});

  const CheckpointInfo info = read_checkpoint_info(file);
  EXPECT_EQ(info.algorithm, "saccm");
  EXPECT_EQ(info.steps, 140);
  auto vec_b = sami_envs(2, 5);
  auto b = make_learner(info.algorithm, *vec_b,
                        {.seed = 77, .hyperparameters = parse_hyperparameter_text(info.config)});
  b->load(file);
  EXPECT_EQ(b->steps(), 140);
  EXPECT_EQ(b->parameter_hash(), saved);
  b->learn(2 * 130, {});
  EXPECT_EQ(b->steps(), 260);
  EXPECT_NE(b->parameter_hash(), saved);
  EXPECT_EQ(b->parameter_hash(), a->parameter_hash());

  // Another method's checkpoint, other networks or another vector size: refused, unchanged.
  auto tesac = make_learner("tesac", *vec_b, {.hyperparameters = hp});
  EXPECT_TRUE(one_line(user_error([&] { tesac->load(file); })));
  auto wide_hp = hp;
  wide_hp["net_arch"] = "16,16";
  auto wide = make_learner("saccm", *vec_b, {.hyperparameters = wide_hp});
  const std::uint64_t before = wide->parameter_hash();
  EXPECT_FALSE(user_error([&] { wide->load(file); }).empty());
  EXPECT_EQ(wide->parameter_hash(), before);
  auto vec_c = sami_envs(3, 5);
  auto three = make_learner("saccm", *vec_c, {.hyperparameters = hp});
  const std::uint64_t three_before = three->parameter_hash();
  EXPECT_FALSE(user_error([&] { three->load(file); }).empty());
  EXPECT_EQ(three->parameter_hash(), three_before);
  EXPECT_EQ(three->steps(), 0);
  std::filesystem::remove_all(dir);
}

// act() keeps the context it inferred: SamiConfig's context_size floats; a fresh episode starts a
// zeroed stream again, so the same observation gives the same context, and a step later another.
TEST(SamiLearner, ActKeepsTheContextItInferred) {
  auto vec = sami_envs(2, 5);
  vec->reset(5);
  auto learner = make_learner("saccm", *vec, {.seed = 5, .hyperparameters = tiny_hp()});
  EXPECT_TRUE(last_context(*learner).empty());
  const int size = std::stoi(parse_hyperparameter_text(learner->config_text()).at("context_size"));
  std::vector<double> action(vec->action_space().size());
  learner->act(vec->observation(0), action, /*deterministic=*/true);
  const std::vector<float> first(last_context(*learner).begin(), last_context(*learner).end());
  ASSERT_EQ(static_cast<int>(first.size()), size);
  learner->act(vec->observation(0), action, /*deterministic=*/true);
  const std::vector<float> second(last_context(*learner).begin(), last_context(*learner).end());
  EXPECT_NE(second, first);
  learner->new_episode();
  learner->act(vec->observation(0), action, /*deterministic=*/true);
  EXPECT_EQ(std::vector<float>(last_context(*learner).begin(), last_context(*learner).end()),
            first);
  auto ppo = make_learner("ppo", *vec, {});
  EXPECT_TRUE(one_line(user_error([&] { last_context(*ppo); })));
}

TEST(SamiLearner, TesacTrainsOnTeachMyAgent) {
  std::vector<std::unique_ptr<envs::Env>> list;
  for (int i = 0; i < 2; ++i)
    list.push_back(std::make_unique<envs::TmaEnvAdapter>(tma::TmaOptions{}));
  ThreadedVecEnv vec(std::move(list), /*threads=*/1);
  auto learner = make_learner("tesac", vec, {.seed = 2, .hyperparameters = tiny_hp()});
  TrainStats last;
  learner->learn(2 * 120, [&](const TrainStats& s) {
    last = s;
    return true;
  });
  EXPECT_EQ(learner->steps(), 240);
  EXPECT_GT(last.losses.at("updates"), 0);
  EXPECT_TRUE(std::isfinite(last.losses.at("qf_loss")));
  EXPECT_EQ(last.losses.count("sance_loss"), 0u);  // TESAC has no contrastive step
}

// CartPole (float64 observations, actions in [-3, 3]) ends its episodes within 30 steps: every
// episode is one stored trajectory, the autoreset steps none, and the reward hook's rewards are
// the ones trained on.
TEST(SamiLearner, NextStepAutoresetStoresEachEpisodeOnceWithTheHookedRewards) {
  auto vec = testing::make_cartpoles(3, 30);
  long hook_calls = 0;
  bool in_bounds = true;
  const RewardHook hook = [&](const VecEnv&, std::span<const double> actions,
                              std::span<double> rewards) {
    ++hook_calls;
    for (const double a : actions) in_bounds = in_bounds && a >= -3 && a <= 3;
    for (double& r : rewards) r += 1.0;
  };
  auto hp = tiny_hp();
  hp["buffer_size"] = "1000";
  hp["report_every"] = "1000";
  auto learner =
      make_learner("satesac", *vec, {.seed = 4, .hyperparameters = hp, .reward_hook = hook});
  TrainStats last;
  learner->learn(3 * 200, [&](const TrainStats& s) {
    last = s;
    return true;
  });
  EXPECT_EQ(hook_calls, 200);
  EXPECT_TRUE(in_bounds);
  ASSERT_GT(last.episodes, 3);
  EXPECT_EQ(last.losses.at("buffer_trajectories"), last.episodes);
  EXPECT_DOUBLE_EQ(last.episodic_return, 2 * last.episodic_length);  // reward 1, hook 1
  EXPECT_GT(last.losses.at("updates"), 0);
}

TEST(SamiLearner, RefusalsAreOneLineUserErrors) {
  auto vec = sami_envs(2, 1);
  const auto refused = [&](const std::string& algorithm, VecEnv& env,
                           const LearnerOptions& options) {
    const std::string error = user_error([&] { make_learner(algorithm, env, options); });
    EXPECT_FALSE(error.empty()) << algorithm;
    EXPECT_TRUE(one_line(error)) << error;
    return error;
  };
  EXPECT_NE(refused("saccm", *vec, {.hyperparameters = {{"bogus", "1"}}}).find("bogus"),
            std::string::npos);
  refused("saccm", *vec, {.hyperparameters = {{"horizon", "0"}}});
  refused("saccm", *vec, {.hyperparameters = {{"train_freq", "0"}}});
  refused("saccm", *vec, {.hyperparameters = {{"neg_ratio", "2"}}});
  auto one = sami_envs(1, 1);
  refused("ccm", *one, {});
  // An image key.
  auto images = testing::make_cartpoles(1, 30, /*with_image=*/true);
  EXPECT_NE(refused("saccm", *images, {}).find("'eye'"), std::string::npos);
}

}  // namespace
}  // namespace cradle::learn::meta

// PPO and A2C on the inline CartPole: they learn (mean return far above a random policy's),
// are deterministic given the seed, and checkpoints restore them exactly.
#include <gtest/gtest.h>
#include <unistd.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/rng.h"
#include "learn/on_policy.h"
#include "learn/registry.h"
#include "learn/return_normalizer.h"
#include "test_tasks.h"

namespace cradle::learn {
namespace {

constexpr int kMaxSteps = 200;  // CartPole truncation

// Mean return of uniformly random actions over `episodes` CartPole episodes.
double random_return(int episodes) {
  testing::CartPole env(testing::cartpole_model(), kMaxSteps, false);
  Rng rng(5);
  double total = 0;
  env.reset(1);
  for (int e = 0; e < episodes; ++e) {
    if (e > 0) env.reset(std::nullopt);
    for (;;) {
      const double action = rng.uniform(-3, 3);
      const envs::StepResult result = env.step({&action, 1});
      total += result.reward;
      if (result.terminated || result.truncated) break;
    }
  }
  return total / episodes;
}

struct Curve {
  std::vector<double> returns;  // episodic return of each report (NaN-free ones)
  std::vector<double> losses;   // every loss value of every report, in order
  double last_return() const { return returns.empty() ? 0.0 : returns.back(); }
  // Mean of the last k reported returns.
  double final_return(int k) const {
    double sum = 0;
    int n = 0;
    for (int i = static_cast<int>(returns.size()) - 1; i >= 0 && n < k; --i, ++n) sum += returns[i];
    return n > 0 ? sum / n : 0.0;
  }
};

Curve train(Learner& learner, long steps) {
  Curve curve;
  learner.learn(steps, [&](const TrainStats& stats) {
    if (!std::isnan(stats.episodic_return)) curve.returns.push_back(stats.episodic_return);
    for (const auto& [name, value] : stats.losses) {
      if (!name.ends_with("_seconds")) curve.losses.push_back(value);  // timings vary
    }
    return true;
  });
  return curve;
}

// Observations to compare actions on: the first observations of a few CartPole episodes.
std::vector<envs::ObservationBuffers> probe_observations(bool with_image) {
  auto env = testing::make_cartpoles(1, kMaxSteps, with_image);
  std::vector<envs::ObservationBuffers> observations;
  env->reset(123);
  const std::vector<double> push = {1.5};
  for (int i = 0; i < 5; ++i) {
    observations.push_back(env->observation(0));
    env->step(push);
  }
  return observations;
}

std::vector<double> actions_of(Learner& learner, const std::vector<envs::ObservationBuffers>& obs,
                               bool deterministic) {
  std::vector<double> actions;
  for (const auto& o : obs) {
    double a = 0;
    learner.act(o, {&a, 1}, deterministic);
    actions.push_back(a);
  }
  return actions;
}

TEST(Ppo, LearnsCartPole) {
  const double baseline = random_return(200);
  auto env = testing::make_cartpoles(2, kMaxSteps);
  LearnerOptions options{.seed = 1, .hyperparameters = {{"n_steps", "1024"}}};
  auto learner = make_learner("ppo", *env, options);
  const Curve curve = train(*learner, 30'000);
  ASSERT_FALSE(curve.returns.empty());
  const double learned = curve.final_return(3);
  std::printf("random %.1f -> ppo %.1f (first report %.1f)\n", baseline, learned,
              curve.returns.front());
  EXPECT_GT(learned, 5 * baseline);
  EXPECT_GT(learned, 100.0);
  EXPECT_GE(learner->steps(), 30'000);

  // Deterministic evaluation actions stay inside the bounds.
  for (double a : actions_of(*learner, probe_observations(false), true)) {
    EXPECT_LE(std::fabs(a), 3.0);
  }
}

TEST(Ppo, ValueHeadRisesAsItLearnsTheReturn) {
  // CartPole pays 1 per step: the value of a start state grows from about 0 toward the
  // discounted episode length as the value head trains (SPDL's estimate of a task).
  auto env = testing::make_cartpoles(2, kMaxSteps);
  auto learner = make_learner(
      "ppo", *env, {.seed = 3, .hyperparameters = {{"n_steps", "256"}, {"shared_layers", "32"}}});
  const std::vector<envs::ObservationBuffers> probes = probe_observations(false);
  const double before = learner->value(probes[0]);
  EXPECT_LT(std::fabs(before), 2.0);
  EXPECT_EQ(learner->value(probes[0]), before);  // no statistics change in between
  train(*learner, 5'000);
  const double after = learner->value(probes[0]);
  EXPECT_GT(after, before + 3.0);
}

TEST(A2c, ImprovesOnCartPole) {
  const double baseline = random_return(200);
  auto env = testing::make_cartpoles(4, kMaxSteps);
  LearnerOptions options{.seed = 2};
  auto learner = make_learner("a2c", *env, options);
  const Curve curve = train(*learner, 30'000);
  ASSERT_FALSE(curve.returns.empty());
  const double learned = curve.final_return(3);
  std::printf("random %.1f -> a2c %.1f (first report %.1f)\n", baseline, learned,
              curve.returns.front());
  EXPECT_GT(learned, 3 * baseline);
}

// Two learners with the same seed and options train identically.
TEST(Ppo, DeterministicGivenTheSeed) {
  const std::map<std::string, std::string> small = {
      {"n_steps", "64"}, {"batch_size", "32"}, {"n_epochs", "2"}};
  auto env_a = testing::make_cartpoles(2, 30, /*with_image=*/true);
  auto env_b = testing::make_cartpoles(2, 30, /*with_image=*/true);
  auto a = make_learner("ppo", *env_a, {.seed = 7, .hyperparameters = small});
  auto b = make_learner("ppo", *env_b, {.seed = 7, .hyperparameters = small});
  EXPECT_EQ(train(*a, 512).losses, train(*b, 512).losses);
  const auto probes = probe_observations(true);
  EXPECT_EQ(actions_of(*a, probes, true), actions_of(*b, probes, true));
  EXPECT_EQ(actions_of(*a, probes, false), actions_of(*b, probes, false));
}

// save -> load into a learner built with another seed: identical actions (deterministic and
// sampled), and continuing both gives identical training.
void check_checkpoint(const std::string& algorithm, bool with_image,
                      const std::map<std::string, std::string>& hyperparameters) {
  SCOPED_TRACE(algorithm);
  // Named by the test and the process: ctest -j runs the tests that call this side by side.
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() /
      ("cradle_" + algorithm + "_" +
       ::testing::UnitTest::GetInstance()->current_test_info()->name() + "_" +
       std::to_string(getpid()) + "_checkpoint.pt");
  auto env_a = testing::make_cartpoles(2, 30, with_image);
  auto env_b = testing::make_cartpoles(2, 30, with_image);
  auto a = make_learner(algorithm, *env_a, {.seed = 3, .hyperparameters = hyperparameters});
  auto b = make_learner(algorithm, *env_b, {.seed = 99, .hyperparameters = hyperparameters});
  train(*a, 256);
  a->save(file);
  EXPECT_FALSE(std::filesystem::exists(file.string() + ".tmp"));
  b->load(file);
  EXPECT_EQ(b->steps(), a->steps());

  const CheckpointInfo info = read_checkpoint_info(file);
  EXPECT_EQ(info.algorithm, algorithm);
  EXPECT_EQ(info.steps, a->steps());
  EXPECT_EQ(info.config, a->config_text());

  const auto probes = probe_observations(with_image);
  EXPECT_EQ(actions_of(*a, probes, true), actions_of(*b, probes, true));
  EXPECT_EQ(actions_of(*a, probes, false), actions_of(*b, probes, false));

  // Resume: both continue from the save point (the sampled actions above drew the same numbers
  // from both generators) and must train identically.
  const Curve continued = train(*a, 768);
  const Curve resumed = train(*b, 768);
  EXPECT_FALSE(continued.losses.empty());
  EXPECT_EQ(continued.losses, resumed.losses);
  EXPECT_EQ(continued.returns, resumed.returns);
  EXPECT_EQ(actions_of(*a, probes, true), actions_of(*b, probes, true));
  std::filesystem::remove(file);
}

TEST(Checkpoint, PpoWithImagesRestoresExactly) {
  check_checkpoint("ppo", true, {{"n_steps", "64"}, {"batch_size", "32"}, {"n_epochs", "2"}});
}

TEST(Checkpoint, A2cRestoresExactly) { check_checkpoint("a2c", false, {}); }

TEST(Checkpoint, PpoReturnNormalizerIsSavedAndRestoredBitwise) {
  // normalize_returns scales every reward by the return statistics: a resumed run continues
  // exactly only with them (check_checkpoint trains both on and compares every loss).
  const std::map<std::string, std::string> hp = {
      {"n_steps", "64"}, {"batch_size", "32"}, {"n_epochs", "2"}, {"normalize_returns", "true"}};
  check_checkpoint("ppo", false, hp);

  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / "cradle_ppo_return_statistics.pt";
  auto env = testing::make_cartpoles(2, 30);
  auto a = make_learner("ppo", *env, {.seed = 3, .hyperparameters = hp});
  auto b = make_learner("ppo", *env, {.seed = 4, .hyperparameters = hp});
  train(*a, 256);
  a->save(file);
  b->load(file);
  const auto statistics = [](const Learner& learner) {
    return dynamic_cast<const OnPolicyLearner&>(learner).return_normalizer()->statistics();
  };
  const ReturnStatistics saved = statistics(*a), loaded = statistics(*b);
  EXPECT_GT(saved.count, 200);  // every real step of the rollouts (256 less the autoresets)
  EXPECT_NE(saved.var, 1.0);
  EXPECT_EQ(std::bit_cast<std::uint64_t>(loaded.mean), std::bit_cast<std::uint64_t>(saved.mean));
  EXPECT_EQ(std::bit_cast<std::uint64_t>(loaded.var), std::bit_cast<std::uint64_t>(saved.var));
  EXPECT_EQ(std::bit_cast<std::uint64_t>(loaded.count), std::bit_cast<std::uint64_t>(saved.count));

  // A checkpoint of the other setting is refused with one line, in both directions.
  auto plain =
      make_learner("ppo", *env, {.hyperparameters = {{"n_steps", "64"}, {"batch_size", "32"}}});
  try {
    plain->load(file);
    ADD_FAILURE() << "loaded a normalize_returns checkpoint without it";
  } catch (const UserError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("normalize_returns is false but the checkpoint was trained with "
                           "normalize_returns = true"),
              std::string::npos)
        << message;
    EXPECT_EQ(message.find('\n'), std::string::npos);
  }
  plain->save(file);
  try {
    b->load(file);
    ADD_FAILURE() << "loaded a checkpoint without return statistics into normalize_returns";
  } catch (const UserError& error) {
    EXPECT_NE(std::string(error.what()).find("normalize_returns is true"), std::string::npos)
        << error.what();
  }
  // The statistics are left as they were.
  EXPECT_EQ(statistics(*b), saved);
  std::filesystem::remove(file);
}

TEST(Ppo, NormalizeReturnsScalesTheTrainedRewards) {
  // CartPole pays 1 per step; with normalize_returns the episodic return the learner reports
  // (the rewards it trained on) is far below the episode length.
  auto env = testing::make_cartpoles(1, 20);
  auto learner =
      make_learner("ppo", *env,
                   {.hyperparameters = {
                        {"n_steps", "200"}, {"batch_size", "50"}, {"normalize_returns", "true"}}});
  double trained = 0;
  learner->learn(200, [&](const TrainStats& s) {
    trained = s.episodic_return;
    return true;
  });
  EXPECT_LT(trained, 20.0);
  EXPECT_GT(trained, 0.0);
}

TEST(Checkpoint, RejectsWrongAlgorithmShapeAndMissingFiles) {
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / "cradle_reject_checkpoint.pt";
  auto env = testing::make_cartpoles(1, 30);
  auto ppo =
      make_learner("ppo", *env, {.hyperparameters = {{"n_steps", "16"}, {"batch_size", "16"}}});
  ppo->save(file);
  auto a2c = make_learner("a2c", *env, {});
  EXPECT_THROW(a2c->load(file), UserError);
  auto wide = make_learner("ppo", *env, {.hyperparameters = {{"pi_layers", "32"}}});
  EXPECT_THROW(wide->load(file), UserError);
  auto raw = make_learner("ppo", *env, {.hyperparameters = {{"normalize_observations", "false"}}});
  EXPECT_THROW(raw->load(file), UserError);
  EXPECT_THROW(ppo->load(file.string() + ".missing"), UserError);
  EXPECT_THROW(make_learner("dqn", *env, {}), UserError);
  EXPECT_THROW(make_learner("ppo", *env, {.hyperparameters = {{"n_stepz", "1"}}}), UserError);
  std::filesystem::remove(file);
}

// The reward hook sees every step and its changes are what the learner trains on.
TEST(Ppo, RewardHookChangesTheTrainedReward) {
  auto env = testing::make_cartpoles(2, 20);
  long calls = 0;
  LearnerOptions options{.seed = 4, .hyperparameters = {{"n_steps", "32"}}};
  options.reward_hook = [&](const VecEnv& vec, std::span<const double> actions,
                            std::span<double> rewards) {
    ++calls;
    EXPECT_EQ(actions.size(), 2u);
    EXPECT_EQ(rewards.size(), static_cast<size_t>(vec.num_envs()));
    for (double& r : rewards) r += 10.0;
  };
  auto learner = make_learner("ppo", *env, options);
  double episodic_return = 0, episodic_length = 0;
  learner->learn(640, [&](const TrainStats& stats) {
    if (!std::isnan(stats.episodic_return)) {
      episodic_return = stats.episodic_return;
      episodic_length = stats.episodic_length;
    }
    return true;
  });
  EXPECT_EQ(calls, 640 / 2);
  EXPECT_DOUBLE_EQ(episodic_return, 11.0 * episodic_length);
}

}  // namespace
}  // namespace cradle::learn

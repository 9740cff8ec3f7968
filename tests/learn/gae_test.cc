// Advantage estimation, the rollout collector's handling of episode ends, observation
// preprocessing (touch pooling, running normalisation) and hyperparameter parsing.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <set>
#include <vector>

#include "core/error.h"
#include "envs/babybench.h"
#include "learn/hyperparams.h"
#include "learn/networks.h"
#include "learn/preprocess.h"
#include "learn/rollout.h"
#include "senses/touch.h"
#include "test_tasks.h"

namespace cradle::learn {
namespace {

// One env through a termination, an autoreset step, a truncation and another autoreset step;
// a second env with no episode end checks the [step][env] layout. gamma 0.9, lambda 0.8.
TEST(Gae, HandComputedExample) {
  const int steps = 5, envs = 2;
  // Row-major [step][env]: env 0 first in each pair.
  const std::vector<float> rewards = {1, 1, 2, 1, 0, 1, 1, 1, 0, 1};
  const std::vector<float> values = {0.5, 0, 1.0, 0, 3.0, 0, 2.0, 0, 4.0, 0};
  const std::vector<float> last_values = {1.5, 0};
  const std::vector<std::uint8_t> terminated = {0, 0, 1, 0, 0, 0, 0, 0, 0, 0};
  const std::vector<std::uint8_t> dones = {0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
  std::vector<float> advantages(10), returns(10);
  compute_gae(steps, envs, rewards, values, last_values, terminated, dones, 0.9, 0.8, advantages,
              returns);
  // Env 0, backwards:
  //   t4 (autoreset step): delta = 0 + 0.9 * 1.5 - 4 = -2.65                      A = -2.65
  //   t3 (truncated, bootstraps V(final obs) = values[t4] = 4): 1 + 3.6 - 2 = 2.6  A = 2.6
  //   t2 (autoreset step): 0 + 0.9 * 2 - 3 = -1.2, + 0.72 * 2.6                   A = 0.672
  //   t1 (terminated, no bootstrap): 2 - 1 = 1                                     A = 1
  //   t0: 1 + 0.9 * 1 - 0.5 = 1.4, + 0.72 * 1                                      A = 2.12
  const std::vector<double> expected0 = {2.12, 1.0, 0.672, 2.6, -2.65};
  // Env 1: every delta is 1, A_t = 1 + 0.72 A_{t+1}.
  const std::vector<double> expected1 = {2.88038656, 2.611648, 2.2384, 1.72, 1.0};
  for (int t = 0; t < steps; ++t) {
    EXPECT_NEAR(advantages[2 * t], expected0[t], 1e-5) << "t=" << t;
    EXPECT_NEAR(returns[2 * t], expected0[t] + values[2 * t], 1e-5) << "t=" << t;
    EXPECT_NEAR(advantages[2 * t + 1], expected1[t], 1e-5) << "t=" << t;
    EXPECT_NEAR(returns[2 * t + 1], expected1[t], 1e-5) << "t=" << t;
  }
}

// With lambda 1 and no bootstrap (terminated), the advantage is the discounted return minus V.
TEST(Gae, LambdaOneIsMonteCarlo) {
  const std::vector<float> rewards = {1, 2, 3}, values = {0.5, 0.25, 0.125}, last = {9};
  const std::vector<std::uint8_t> terminated = {0, 0, 1}, dones = {0, 0, 1};
  std::vector<float> advantages(3), returns(3);
  compute_gae(3, 1, rewards, values, last, terminated, dones, 0.5, 1.0, advantages, returns);
  EXPECT_NEAR(returns[0], 1 + 0.5 * 2 + 0.25 * 3, 1e-6);
  EXPECT_NEAR(returns[1], 2 + 0.5 * 3, 1e-6);
  EXPECT_NEAR(returns[2], 3, 1e-6);
}

// The collector stores the step after every episode end as an invalid (autoreset) row, counts
// truncations as done but not terminated, and bootstraps truncated rows from the next row's
// value, which is the value of the episode's final observation.
TEST(RolloutCollector, MarksAutoresetStepsAndTruncations) {
  auto env = testing::make_cartpoles(2, /*max_steps=*/3);
  at::Generator generator = at::make_generator<at::CPUGeneratorImpl>(3);
  ObservationPipeline pipeline(env->observation_space(), {}, nullptr);
  GaussianActorCritic policy(pipeline.shape(), 1, PolicyConfig{}, generator);
  RolloutBuffer buffer(40, 2, pipeline.shape(), 1);
  RolloutCollector collector(*env, pipeline, nullptr);
  collector.start(11);
  collector.collect(policy, generator, buffer);

  const auto* done = buffer.dones.data_ptr<std::uint8_t>();
  const auto* terminal = buffer.terminated.data_ptr<std::uint8_t>();
  const auto* valid = buffer.valid.data_ptr<std::uint8_t>();
  int truncations = 0;
  for (int e = 0; e < 2; ++e) {
    int length = 0;
    for (int t = 0; t < 40; ++t) {
      const int row = t * 2 + e;
      const bool after_end = t > 0 && done[row - 2];
      EXPECT_EQ(valid[row], after_end ? 0 : 1) << "t=" << t << " env=" << e;
      if (!valid[row]) {
        EXPECT_EQ(done[row], 0);
        length = 0;
        continue;
      }
      ++length;
      ASSERT_LE(length, 3);
      if (done[row] && !terminal[row]) {
        EXPECT_EQ(length, 3);  // truncated exactly at max_steps
        ++truncations;
      }
    }
  }
  EXPECT_GT(truncations, 0);

  // Truncated rows bootstrap: with one step of lambda = 0 the return is r + gamma V(next row).
  buffer.compute_returns_and_advantages(0.9, 0.0);
  const float* values = buffer.values.data_ptr<float>();
  const float* returns = buffer.returns.data_ptr<float>();
  const float* rewards = buffer.rewards.data_ptr<float>();
  for (int row = 0; row + 2 < 80; ++row) {
    if (!valid[row]) continue;
    const double next = terminal[row] ? 0.0 : 0.9 * values[row + 2];
    EXPECT_NEAR(returns[row], rewards[row] + next, 1e-5);
  }
}

// ---------------------------------------------------------------------------------------------
// Preprocessing

Config selftouch_config() {
  return load_config(std::filesystem::path(CRADLE_SOURCE_DIR) / "configs" / "config_selftouch.yml");
}

TEST(TouchPooling, OneSumOfForceMagnitudesPerGeomWithSensors) {
  const auto assets = envs::make_assets(selftouch_config());
  const senses::Touch& touch = *assets->touch;
  ASSERT_EQ(touch.values_per_sensor(), 3);  // force_vector
  const TouchPooling pooling(assets->touch_layout);

  // One output per MIMo geom that carries sensors.
  std::vector<int> sensors_on_geom(assets->model->ngeom, 0);
  for (const int geom : touch.sensor_geoms()) ++sensors_on_geom[geom];
  const int geoms_with_sensors = static_cast<int>(
      std::count_if(sensors_on_geom.begin(), sensors_on_geom.end(), [](int n) { return n > 0; }));
  EXPECT_EQ(pooling.size(), geoms_with_sensors);
  EXPECT_GT(pooling.size(), 10);
  EXPECT_LE(pooling.size(), 36);  // MIMo v1 has 36 geoms
  EXPECT_EQ(pooling.input_size(), touch.size());

  // A hand-made skin reading: sensor s pushes with (s % 5 - 2, 0.5, -(s % 3)), except every
  // fourth sensor, which feels nothing.
  std::vector<float> raw(touch.size());
  std::vector<double> expected(assets->model->ngeom, 0.0);
  for (int s = 0; s < touch.sensor_count(); ++s) {
    if (s % 4 == 0) continue;
    const float f[3] = {static_cast<float>(s % 5 - 2), 0.5f, -static_cast<float>(s % 3)};
    std::copy(f, f + 3, raw.begin() + 3 * s);
    expected[touch.sensor_geoms()[s]] += std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
  }
  std::vector<float> pooled(pooling.size());
  pooling.pool(raw, pooled);
  for (int k = 0; k < pooling.size(); ++k) {
    const int geom = pooling.geoms()[k];
    EXPECT_GT(sensors_on_geom[geom], 0);
    EXPECT_NEAR(pooled[k], expected[geom], 1e-3 * expected[geom]) << "geom " << geom;
  }

  // In the pipeline the touch key shrinks to the pooled size; pool_touch = false keeps it raw.
  const envs::BabyBenchEnv env(assets);
  const DictSpace& space = env.observation_space();
  const int proprio = space.find("observation")->size();
  ASSERT_EQ(env.layout("touch"), &assets->touch_layout);  // the env publishes its skin
  EXPECT_EQ(env.layout("observation"), nullptr);
  ObservationPipeline pooled_pipeline(space, {}, env.layout("touch"));
  EXPECT_EQ(pooled_pipeline.shape().vector_size, proprio + pooling.size() + 6);
  ObservationPipeline raw_pipeline(space, {.pool_touch = false}, nullptr);
  EXPECT_EQ(raw_pipeline.shape().vector_size, proprio + touch.size() + 6);
  EXPECT_THROW((void)ObservationPipeline(space, {}, nullptr), UserError);
}

TEST(RunningMeanStd, MatchesBatchStatistics) {
  RunningMeanStd stats(2);
  const std::vector<float> a = {1, 10, 3, 20}, b = {5, 30, 7, 40, 9, 50};
  stats.update(a, 2);
  stats.update(b, 3);
  // Mean and population variance of {1,3,5,7,9} and {10,...,50} (5, 8 and 30, 200), merged
  // with the prior pseudo-count c at mean 0, variance 1:
  //   mean = 5 m / (5 + c),  var = (c + 5 v + m^2 c 5 / (5 + c)) / (5 + c).
  const double c = RunningMeanStd::kInitialCount, n = 5 + c;
  EXPECT_NEAR(stats.mean()[0], 5 * 5.0 / n, 1e-9);
  EXPECT_NEAR(stats.mean()[1], 5 * 30.0 / n, 1e-9);
  EXPECT_NEAR(stats.var()[0], (c + 5 * 8.0 + 25.0 * c * 5 / n) / n, 1e-9);
  EXPECT_NEAR(stats.var()[1], (c + 5 * 200.0 + 900.0 * c * 5 / n) / n, 1e-9);
  EXPECT_DOUBLE_EQ(stats.count(), n);
  std::vector<float> out(2);
  stats.normalize(std::vector<float>{5, 1e6}, out, 10.0);
  EXPECT_NEAR(out[0], (5 - stats.mean()[0]) / std::sqrt(stats.var()[0] + 1e-8), 1e-5);
  EXPECT_EQ(out[1], 10.0f);  // clipped
}

TEST(Hyperparameters, ParseApplyAndRoundTrip) {
  int n = 3;
  double lr = 3e-4;
  bool flag = false;
  std::vector<int> layers{64, 64};
  std::string activation = "tanh";
  Hyperparameters table;
  table.add("n", &n, "an int");
  table.add("lr", &lr, "a double");
  table.add("flag", &flag, "a bool");
  table.add("layers", &layers, "sizes");
  table.add("activation", &activation, "a string");
  table.apply({{"n", "7"}, {"lr", "0.001"}, {"flag", "true"}, {"layers", "32,16,8"}});
  EXPECT_EQ(n, 7);
  EXPECT_DOUBLE_EQ(lr, 0.001);
  EXPECT_TRUE(flag);
  EXPECT_EQ(layers, (std::vector<int>{32, 16, 8}));
  EXPECT_THROW(table.apply({{"m", "1"}}), UserError);
  EXPECT_THROW(table.apply({{"n", "1.5"}}), UserError);
  EXPECT_THROW(table.apply({{"flag", "yes please"}}), UserError);

  const std::string text = table.to_text();
  n = 0;
  lr = 0;
  layers.clear();
  table.apply(parse_hyperparameter_text(text));
  EXPECT_EQ(n, 7);
  EXPECT_DOUBLE_EQ(lr, 0.001);
  EXPECT_EQ(layers, (std::vector<int>{32, 16, 8}));
  table.apply({{"layers", ""}});
  EXPECT_TRUE(layers.empty());
}

TEST(ObservationPipeline, PolicyImagesFalseDropsOnlyTheImageKeys) {
  DictSpace space;
  space.entries.push_back({"observation", Box::unbounded({7}, DType::kFloat64)});
  space.entries.push_back({"eye_left", Box::uniform({8, 6, 3}, DType::kUInt8, 0, 255)});
  space.entries.push_back({"eye_right", Box::uniform({8, 6, 3}, DType::kUInt8, 0, 255)});
  const ObservationPipeline seeing(space, {}, nullptr);
  EXPECT_EQ(seeing.shape().vector_size, 7);
  ASSERT_EQ(seeing.shape().images.size(), 2u);
  EXPECT_EQ(seeing.shape().images[1], (std::array<int, 3>{8, 6, 3}));
  const ObservationPipeline blind(space, {.policy_images = false}, nullptr);
  EXPECT_EQ(blind.shape().vector_size, 7);
  EXPECT_TRUE(blind.shape().images.empty());
  // A checkpoint taken with images refuses a run without them, and the reverse.
  EXPECT_THROW(blind.config().check_matches("policy_images = true\n"), UserError);
  EXPECT_NO_THROW(blind.config().check_matches("policy_images = false\n"));
}

}  // namespace
}  // namespace cradle::learn

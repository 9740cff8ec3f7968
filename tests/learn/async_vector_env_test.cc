// The asynchronous vector env on the inline CartPole: batches of distinct held ids, per-env
// determinism whatever the batches (against the lock-step vector), next-step autoreset, one-line
// errors for wrong ids and sizes, and PPO learning with async collection.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <set>
#include <thread>
#include <vector>

#include "core/error.h"
#include "learn/registry.h"
#include "learn/vector_env.h"
#include "test_tasks.h"

namespace cradle::learn {
namespace {

using testing::CartPole;

// A CartPole that takes a varying wall time per step (up to 0.3 ms, from its id and step count),
// so that the order in which envs finish, and thus the batches, vary from run to run.
class SlowCartPole final : public envs::Env {
 public:
  SlowCartPole(int id, int max_steps)
      : id_(id), inner_(testing::cartpole_model(), max_steps, false) {}
  const DictSpace& observation_space() const override { return inner_.observation_space(); }
  const Box& action_space() const override { return inner_.action_space(); }
  const envs::ObservationBuffers& observation() const override { return inner_.observation(); }
  const envs::Info& info() const override { return inner_.info(); }
  void reset(std::optional<std::uint64_t> seed) override { inner_.reset(seed); }
  envs::StepResult step(std::span<const double> action) override {
    std::this_thread::sleep_for(std::chrono::microseconds(((id_ * 7 + calls_++ * 3) % 4) * 100));
    return inner_.step(action);
  }

 private:
  int id_;
  int calls_ = 0;
  CartPole inner_;
};

std::vector<std::unique_ptr<envs::Env>> slow_cartpoles(int n, int max_steps) {
  std::vector<std::unique_ptr<envs::Env>> list;
  for (int i = 0; i < n; ++i) list.push_back(std::make_unique<SlowCartPole>(i, max_steps));
  return list;
}

std::vector<std::unique_ptr<envs::Env>> cartpoles(int n, int max_steps) {
  std::vector<std::unique_ptr<envs::Env>> list;
  for (int i = 0; i < n; ++i) {
    list.push_back(std::make_unique<CartPole>(testing::cartpole_model(), max_steps, false));
  }
  return list;
}

// The action env e takes at its k-th step: a fixed function of both, nothing else.
double action_of(int e, int k) { return 2.5 * std::sin(0.9 * k + 1.7 * e); }

// What one env saw at each of its steps: the state, reward and flags after it.
struct Step {
  std::vector<double> state;
  double reward;
  bool terminated, truncated;
  friend bool operator==(const Step&, const Step&) = default;
};
using Trajectories = std::vector<std::vector<Step>>;

Step record(const VecEnv& vec, int e, double reward, bool terminated, bool truncated) {
  const std::span<const double> s = vec.observation(e).f64(0);
  return {{s.begin(), s.end()}, reward, terminated, truncated};
}

// `steps` steps of every env in lock-step.
Trajectories lockstep(int n, int steps, int max_steps, std::uint64_t seed) {
  ThreadedVecEnv vec(cartpoles(n, max_steps), 1);
  vec.reset(seed);
  Trajectories out(n);
  std::vector<double> actions(n);
  for (int k = 0; k < steps; ++k) {
    for (int e = 0; e < n; ++e) actions[e] = action_of(e, k);
    vec.step(actions);
    for (int e = 0; e < n; ++e) {
      out[e].push_back(record(vec, e, vec.rewards()[e], vec.terminated()[e], vec.truncated()[e]));
    }
  }
  return out;
}

// `steps` steps of every env through send/recv; checks every batch on the way.
Trajectories async_run(AsyncVecEnv& vec, int steps, std::uint64_t seed) {
  const int n = vec.num_envs();
  vec.reset(seed);
  EXPECT_EQ(vec.held(), n);
  Trajectories out(n);
  std::vector<double> actions(n);
  std::vector<int> ids(n);
  for (int e = 0; e < n; ++e) {
    ids[e] = e;
    actions[e] = action_of(e, 0);
  }
  vec.send(actions, ids);
  int running = n;
  while (running > 0) {
    const AsyncVecEnv::Batch batch = vec.recv();
    EXPECT_EQ(batch.size(), std::min(vec.batch_size(), running));
    std::set<int> distinct(batch.ids.begin(), batch.ids.end());
    EXPECT_EQ(distinct.size(), batch.ids.size());
    ids.clear();
    actions.clear();
    for (int j = 0; j < batch.size(); ++j) {
      const int e = batch.ids[j];
      EXPECT_GE(e, 0);
      EXPECT_LT(e, n);
      // The batch's results are the env's own.
      EXPECT_EQ(batch.rewards[j], vec.rewards()[e]);
      out[e].push_back(record(vec, e, batch.rewards[j], batch.terminated[j], batch.truncated[j]));
      const int k = static_cast<int>(out[e].size());
      if (k < steps) {
        ids.push_back(e);
        actions.push_back(action_of(e, k));
      } else {
        --running;
      }
    }
    vec.send(actions, ids);
  }
  EXPECT_EQ(vec.held(), n);
  return out;
}

TEST(AsyncVecEnv, BatchesAreTheFirstReadyDistinctHeldEnvs) {
  AsyncVecEnv vec(slow_cartpoles(6, 50), /*batch_size=*/2, /*threads=*/2);
  EXPECT_EQ(vec.num_envs(), 6);
  EXPECT_EQ(vec.batch_size(), 2);
  EXPECT_EQ(vec.threads(), 2);
  vec.reset(3);
  const std::vector<int> all = {0, 1, 2, 3, 4, 5};
  vec.send(std::vector<double>(6, 0.5), all);
  EXPECT_EQ(vec.held(), 0);
  std::vector<int> received(6, 0);
  for (int r = 0; r < 60; ++r) {
    const AsyncVecEnv::Batch batch = vec.recv();
    ASSERT_EQ(batch.size(), 2);
    EXPECT_NE(batch.ids[0], batch.ids[1]);
    // Only this batch is held: everything else keeps stepping.
    EXPECT_EQ(vec.held(), 2);
    for (int e : batch.ids) ++received[e];
    const std::vector<int> ids(batch.ids.begin(), batch.ids.end());
    vec.send(std::vector<double>(2, 0.5), ids);
  }
  // Every env keeps being stepped (none starves behind the others).
  for (int e = 0; e < 6; ++e) EXPECT_GE(received[e], 10) << "env " << e;
}

TEST(AsyncVecEnv, EachEnvFollowsItsSeedAndActionsWhateverTheBatches) {
  constexpr int kEnvs = 5, kSteps = 40, kMaxSteps = 12;  // several episodes each: autoresets too
  const Trajectories expected = lockstep(kEnvs, kSteps, kMaxSteps, 11);
  for (auto [batch, threads] : {std::pair{2, 2}, std::pair{1, 3}, std::pair{3, 2}}) {
    AsyncVecEnv vec(slow_cartpoles(kEnvs, kMaxSteps), batch, threads);
    const Trajectories got = async_run(vec, kSteps, 11);
    for (int e = 0; e < kEnvs; ++e) {
      EXPECT_EQ(got[e], expected[e])
          << "env " << e << ", batch " << batch << ", " << threads << " threads";
    }
  }
  // Another seed gives other trajectories (the comparison can fail).
  AsyncVecEnv vec(cartpoles(kEnvs, kMaxSteps), 2, 2);
  EXPECT_NE(async_run(vec, kSteps, 12)[0], expected[0]);
}

TEST(AsyncVecEnv, AutoresetsOnTheStepAfterAnEpisodeEnds) {
  constexpr int kMaxSteps = 4;
  AsyncVecEnv vec(cartpoles(3, kMaxSteps), 1, 2);
  vec.reset(5);
  std::vector<int> steps(3, 0), ended(3, 0);
  std::vector<std::vector<double>> first(3);
  for (int e = 0; e < 3; ++e) {
    const std::span<const double> s = vec.observation(e).f64(0);
    first[e].assign(s.begin(), s.end());
  }
  vec.send(std::vector<double>(3, 0.0), std::vector<int>{0, 1, 2});
  int resets = 0;
  for (int r = 0; r < 60; ++r) {
    const AsyncVecEnv::Batch batch = vec.recv();
    ASSERT_EQ(batch.size(), 1);
    const int e = batch.ids[0];
    if (ended[e]) {
      // The autoreset step: no reward, no flags, a fresh episode's first state.
      EXPECT_EQ(batch.rewards[0], 0.0);
      EXPECT_FALSE(batch.terminated[0] || batch.truncated[0]);
      EXPECT_EQ(vec.info(e).steps, 0);
      EXPECT_LT(std::fabs(vec.observation(e).f64(0)[1]), 0.011);
      ++resets;
      ended[e] = 0;
      steps[e] = 0;
    } else {
      EXPECT_EQ(batch.rewards[0], 1.0);
      ++steps[e];
      EXPECT_EQ(batch.truncated[0], steps[e] == kMaxSteps);
      ended[e] = batch.terminated[0] || batch.truncated[0];
    }
    vec.send(std::vector<double>{0.0}, std::vector<int>{e});
  }
  EXPECT_GE(resets, 6);
}

TEST(AsyncVecEnv, RefusesWrongIdsAndSizesInOneLine) {
  const auto one_line = [](auto&& fn) {
    try {
      fn();
    } catch (const UserError& error) {
      EXPECT_EQ(std::string(error.what()).find('\n'), std::string::npos) << error.what();
      return true;
    }
    return false;
  };
  EXPECT_TRUE(one_line([] { AsyncVecEnv(cartpoles(2, 10), 0, 1); }));
  EXPECT_TRUE(one_line([] { AsyncVecEnv(cartpoles(2, 10), 3, 1); }));
  AsyncVecEnv vec(cartpoles(3, 10), 2, 2);
  vec.reset(1);
  // Nothing in flight yet.
  EXPECT_TRUE(one_line([&] { vec.recv(); }));
  // Sizes, range, repeats.
  EXPECT_TRUE(one_line([&] { vec.send(std::vector<double>(1), std::vector<int>{0, 1}); }));
  EXPECT_TRUE(one_line([&] { vec.send(std::vector<double>(1), std::vector<int>{3}); }));
  EXPECT_TRUE(one_line([&] { vec.send(std::vector<double>(1), std::vector<int>{-1}); }));
  EXPECT_TRUE(one_line([&] { vec.send(std::vector<double>(2), std::vector<int>{1, 1}); }));
  EXPECT_EQ(vec.held(), 3);  // a refused send changes nothing
  vec.send(std::vector<double>(2, 0.1), std::vector<int>{0, 2});
  // Envs in flight are not held: neither sendable nor steppable in lock-step.
  EXPECT_TRUE(one_line([&] { vec.send(std::vector<double>(1), std::vector<int>{0}); }));
  EXPECT_TRUE(one_line([&] { vec.step(std::vector<double>(3)); }));
  const AsyncVecEnv::Batch batch = vec.recv();
  EXPECT_EQ(batch.size(), 2);
  EXPECT_EQ(std::set<int>(batch.ids.begin(), batch.ids.end()), (std::set<int>{0, 2}));
  // All held again: lock-step works, with its own size check.
  EXPECT_TRUE(one_line([&] { vec.step(std::vector<double>(2)); }));
  vec.step(std::vector<double>(3, 0.2));
  EXPECT_EQ(vec.held(), 3);
  EXPECT_TRUE(one_line([&] { vec.recv(); }));
}

// The returns and losses (not the timings) of every report of a PPO run through send/recv, batches
// of 2 of 4 envs.
std::vector<double> async_ppo_trace(std::vector<std::unique_ptr<envs::Env>> envs, int threads,
                                    long steps) {
  AsyncVecEnv vec(std::move(envs), /*batch_size=*/2, threads);
  auto learner = make_learner("ppo", vec, {.seed = 1, .hyperparameters = {{"n_steps", "64"}}});
  std::vector<double> trace;
  learner->learn(steps, [&](const TrainStats& stats) {
    trace.push_back(std::isnan(stats.episodic_return) ? -1.0 : stats.episodic_return);
    for (const auto& [name, value] : stats.losses)
      if (!name.ends_with("_seconds")) trace.push_back(value);  // wall time is not the run
    return true;
  });
  return trace;
}

// With one worker thread the envs finish in the order they were sent (the queue and the ready
// list are FIFO), so the batches, and the whole run, are fixed by the seed: the learning tests
// below use one worker so that their pass/fail does not depend on thread timing. Envs that take
// varying wall time per step give bitwise the same run.
TEST(AsyncVecEnv, OneWorkerFixesTheBatchesWhateverTheTiming) {
  const std::vector<double> fast = async_ppo_trace(cartpoles(4, 200), 1, 1024);
  ASSERT_GE(fast.size(), 8u);
  EXPECT_EQ(async_ppo_trace(slow_cartpoles(4, 200), 1, 1024), fast);
  EXPECT_EQ(async_ppo_trace(cartpoles(4, 200), 1, 1024), fast);
}

// PPO collecting through send/recv learns the CartPole as it does in lock-step. One worker: the
// batches are fixed (above), so the run is the same on an idle and on a loaded machine.
TEST(AsyncVecEnv, PpoLearnsCartPoleWithAsyncCollection) {
  AsyncVecEnv vec(cartpoles(4, 200), /*batch_size=*/2, /*threads=*/1);
  auto learner = make_learner("ppo", vec, {.seed = 1, .hyperparameters = {{"n_steps", "512"}}});
  std::vector<double> returns;
  learner->learn(30'000, [&](const TrainStats& stats) {
    if (!std::isnan(stats.episodic_return)) returns.push_back(stats.episodic_return);
    return true;
  });
  ASSERT_GE(returns.size(), 3u);
  const double last = (returns.end()[-1] + returns.end()[-2] + returns.end()[-3]) / 3;
  std::printf("ppo with async collection: first %.1f -> last %.1f\n", returns.front(), last);
  EXPECT_GE(learner->steps(), 30'000);
  EXPECT_GT(last, 100.0);
  EXPECT_GT(last, 4 * returns.front());
}

// A2C shares the collector: with async collection (5-step rollouts, so each rollout drains the
// envs) it still improves on the CartPole. One worker, for the reason above.
TEST(AsyncVecEnv, A2cImprovesWithAsyncCollection) {
  AsyncVecEnv vec(cartpoles(4, 200), /*batch_size=*/2, /*threads=*/1);
  auto learner = make_learner("a2c", vec, {.seed = 2});
  std::vector<double> returns;
  learner->learn(30'000, [&](const TrainStats& stats) {
    if (!std::isnan(stats.episodic_return)) returns.push_back(stats.episodic_return);
    return true;
  });
  ASSERT_GE(returns.size(), 3u);
  const double last = (returns.end()[-1] + returns.end()[-2] + returns.end()[-3]) / 3;
  std::printf("a2c with async collection: first %.1f -> last %.1f\n", returns.front(), last);
  EXPECT_GT(last, 3 * 5.8);  // three times a random policy's mean return (Ppo tests: 5.8)
}

// The reward hook sees each batch as a vector of its own and its rewards are trained on: every
// CartPole step earns 1, the hook adds 1, so an episode returns twice its length.
TEST(AsyncVecEnv, RewardHookSeesBatchesAndChangesTheReturns) {
  AsyncVecEnv vec(cartpoles(4, 30), /*batch_size=*/3, /*threads=*/2);
  LearnerOptions options{.seed = 2, .hyperparameters = {{"n_steps", "64"}, {"batch_size", "64"}}};
  int calls = 0;
  options.reward_hook = [&](const VecEnv& batch, std::span<const double> actions,
                            std::span<double> rewards) {
    ++calls;
    EXPECT_LE(batch.num_envs(), 3);
    EXPECT_EQ(actions.size(), static_cast<size_t>(batch.num_envs()));
    EXPECT_EQ(rewards.size(), static_cast<size_t>(batch.num_envs()));
    for (double& r : rewards) r += 1.0;
  };
  auto learner = make_learner("ppo", vec, options);
  int reports = 0;
  learner->learn(1024, [&](const TrainStats& stats) {
    ++reports;
    EXPECT_GT(stats.episodes, 0);
    EXPECT_DOUBLE_EQ(stats.episodic_return, 2 * stats.episodic_length);
    return true;
  });
  EXPECT_EQ(reports, 4);
  // One call per batch: at least the 1024 env steps over batches of at most 3.
  EXPECT_GE(calls, 1024 / 3);
}

}  // namespace
}  // namespace cradle::learn

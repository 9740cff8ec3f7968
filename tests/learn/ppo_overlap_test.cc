// overlap_update: PPO (and A2C) collecting rollout k+1 on a thread of their own while updating on
// rollout k. The run depends on its seed and env count only, never on which thread finishes
// first (a collector or learner slowed at irregular points trains bitwise the same), with one or
// two LibTorch threads; off, it is the synchronous loop unchanged; it still learns CartPole; and
// a checkpoint at a boundary resumes exactly.
#include <gtest/gtest.h>
#include <torch/torch.h>
#include <unistd.h>

#include <bit>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include "learn/learner.h"
#include "learn/registry.h"
#include "test_tasks.h"

namespace cradle::learn {
namespace {

using Hp = std::map<std::string, std::string>;

const Hp kSmall = {{"n_steps", "64"}, {"batch_size", "32"}, {"n_epochs", "2"}};

Hp with_overlap(Hp hp) {
  hp["overlap_update"] = "true";
  return hp;
}

// What a run leaves: every report's steps, return and losses (not its timings) as bit patterns
// (a NaN return, no episode ended, equals itself), and the hash of the trained parameters.
struct Trace {
  std::vector<std::uint64_t> values;
  std::uint64_t hash = 0;
  bool operator==(const Trace&) const = default;
};

// Sleeps a few hundred microseconds at irregular calls, to shuffle the threads' interleaving.
void pause(long call) {
  std::this_thread::sleep_for(std::chrono::microseconds(call * 7919 % 5 * 300));
}

struct RunOptions {
  std::string algorithm = "ppo";
  Hp hp = with_overlap(kSmall);
  long steps = 1024;
  int torch_threads = 1;
  bool slow_collector = false;  // the reward hook runs on the collector thread
  bool slow_learner = false;    // the progress callback runs on the learner thread
};

Trace traced_learn(Learner& learner, long steps, bool slow_learner, Trace trace = {}) {
  long reports = 0;
  learner.learn(steps, [&](const TrainStats& stats) {
    if (slow_learner) pause(reports++);
    trace.values.push_back(static_cast<std::uint64_t>(stats.steps));
    trace.values.push_back(std::bit_cast<std::uint64_t>(stats.episodic_return));
    for (const auto& [name, value] : stats.losses) {
      if (!name.ends_with("_seconds")) trace.values.push_back(std::bit_cast<std::uint64_t>(value));
    }
    return true;
  });
  trace.hash = learner.parameter_hash();
  return trace;
}

Trace run(const RunOptions& o) {
  auto env = testing::make_cartpoles(2, 30, /*with_image=*/false);
  LearnerOptions options{.seed = 11, .hyperparameters = o.hp, .torch_threads = o.torch_threads};
  long calls = 0;
  if (o.slow_collector) {
    options.reward_hook = [&](const VecEnv&, std::span<const double>, std::span<double>) {
      pause(calls++);
    };
  }
  auto learner = make_learner(o.algorithm, *env, options);
  const Trace trace = traced_learn(*learner, o.steps, o.slow_learner);
  torch::set_num_threads(1);  // the other tests' setting
  return trace;
}

TEST(PpoOverlap, SameSeedTrainsBitwiseTheSameWhateverTheTiming) {
  const Trace plain = run({});
  EXPECT_FALSE(plain.values.empty());
  EXPECT_EQ(run({}), plain);
  EXPECT_EQ(run({.slow_collector = true}), plain);
  EXPECT_EQ(run({.slow_learner = true}), plain);
}

TEST(PpoOverlap, SameSeedTrainsBitwiseTheSameWithTwoTorchThreads) {
  const Trace two = run({.torch_threads = 2});
  EXPECT_EQ(run({.torch_threads = 2, .slow_collector = true}), two);
  EXPECT_EQ(run({.torch_threads = 2, .slow_learner = true}), two);
}

TEST(PpoOverlap, OffIsTheSynchronousLoopUnchanged) {
  Hp off = kSmall;
  off["overlap_update"] = "false";
  const Trace without_key = run({.hp = kSmall});
  EXPECT_EQ(run({.hp = off}), without_key);
  // And the lag does change the run (the option is not a no-op).
  EXPECT_NE(run({}).hash, without_key.hash);
}

TEST(PpoOverlap, SameStepsAndReportsAsTheSynchronousLoop) {
  // 1,000 steps of 128-step rollouts: 8 rollouts and updates, reports at the same step counts.
  const Hp hp = kSmall;
  RunOptions sync{.hp = hp, .steps = 1000}, overlap{.hp = with_overlap(hp), .steps = 1000};
  auto steps_of = [](const RunOptions& o) {
    auto env = testing::make_cartpoles(2, 30, false);
    auto learner = make_learner(o.algorithm, *env, {.seed = 11, .hyperparameters = o.hp});
    std::vector<long> steps;
    learner->learn(o.steps, [&](const TrainStats& s) {
      steps.push_back(s.steps);
      return true;
    });
    steps.push_back(learner->steps());
    return steps;
  };
  EXPECT_EQ(steps_of(overlap), steps_of(sync));
}

// A report that says stop ends learn() where the synchronous loop would: the envs stepped no
// further than the reported steps (no rollout collected beyond them, none thrown away: the envs'
// training logs and the intrinsic rewards' state see exactly the trained steps).
TEST(PpoOverlap, AReportSayingStopCollectsNoFurther) {
  auto env = testing::make_cartpoles(2, 30, false);
  LearnerOptions options{.seed = 11, .hyperparameters = with_overlap(kSmall)};
  long vector_steps = 0;
  options.reward_hook = [&](const VecEnv&, std::span<const double>, std::span<double>) {
    ++vector_steps;
  };
  auto learner = make_learner("ppo", *env, options);
  std::vector<long> reported;
  learner->learn(100'000, [&](const TrainStats& s) {
    reported.push_back(s.steps);
    return s.steps < 384;
  });
  EXPECT_EQ(reported, (std::vector<long>{128, 256, 384}));
  EXPECT_EQ(learner->steps(), 384);
  EXPECT_EQ(vector_steps * 2, 384);
}

TEST(A2cOverlap, SameSeedTrainsBitwiseTheSameWhateverTheTiming) {
  const RunOptions a2c{.algorithm = "a2c", .hp = with_overlap({}), .steps = 2000};
  const Trace plain = run(a2c);
  RunOptions slow = a2c;
  slow.slow_collector = true;
  EXPECT_EQ(run(slow), plain);
}

TEST(PpoOverlap, LearnsCartPole) {
  // Deterministic (see above), so this holds under any interleaving.
  auto env = testing::make_cartpoles(2, 200, false);
  auto learner = make_learner(
      "ppo", *env,
      {.seed = 1, .hyperparameters = {{"n_steps", "1024"}, {"overlap_update", "true"}}});
  std::vector<double> returns;
  learner->learn(30'000, [&](const TrainStats& s) {
    if (!std::isnan(s.episodic_return)) returns.push_back(s.episodic_return);
    return true;
  });
  ASSERT_GE(returns.size(), 3u);
  const double last = (returns.end()[-1] + returns.end()[-2] + returns.end()[-3]) / 3;
  std::printf("ppo overlap on cartpole: first report %.1f -> last three %.1f\n", returns.front(),
              last);
  EXPECT_GT(last, 100.0);  // a random policy averages about 20
  EXPECT_GT(last, 3 * returns.front());
}

// save at a boundary -> load into a learner built with another seed -> continue: the same as
// continuing the saved learner, and the same as a run that never stopped but was cut into the
// same learn() calls (as the training loop cuts runs at checkpoints), whether the boundary is the
// end of learn()'s budget or a report saying stop.
void check_resume(bool stop_by_callback) {
  SCOPED_TRACE(stop_by_callback ? "stopped by the callback" : "stopped by the budget");
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("cradle_ppo_overlap_" + std::to_string(getpid()) +
                                                "_" + std::to_string(stop_by_callback) + ".pt");
  Hp hp = with_overlap(kSmall);
  hp["normalize_returns"] = "true";
  auto first_leg = [&](Learner& learner) {
    if (!stop_by_callback) return learner.learn(384, nullptr);
    learner.learn(100'000, [](const TrainStats& s) { return s.steps < 384; });
  };
  auto env_a = testing::make_cartpoles(2, 30, false);
  auto env_b = testing::make_cartpoles(2, 30, false);
  auto env_c = testing::make_cartpoles(2, 30, false);
  auto a = make_learner("ppo", *env_a, {.seed = 5, .hyperparameters = hp});
  auto b = make_learner("ppo", *env_b, {.seed = 77, .hyperparameters = hp});
  auto c = make_learner("ppo", *env_c, {.seed = 5, .hyperparameters = hp});
  first_leg(*a);
  EXPECT_EQ(a->steps(), 384);
  a->save(file);
  b->load(file);
  first_leg(*c);
  EXPECT_EQ(b->parameter_hash(), a->parameter_hash());
  const Trace continued = traced_learn(*a, 1024, false);
  const Trace resumed = traced_learn(*b, 1024, false);
  const Trace uninterrupted = traced_learn(*c, 1024, false);
  EXPECT_FALSE(continued.values.empty());
  EXPECT_EQ(resumed, continued);
  EXPECT_EQ(uninterrupted, continued);
  std::filesystem::remove(file);
}

TEST(PpoOverlap, ResumeAtABoundaryIsExact) {
  check_resume(false);
  check_resume(true);
}

}  // namespace
}  // namespace cradle::learn

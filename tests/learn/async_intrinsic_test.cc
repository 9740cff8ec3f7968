// Intrinsic rewards on an async vector's batches: the rewards that keep per-env state index it by
// env id (VecEnv::env_id), so computing them over BatchViews of batches in any order gives each env
// exactly the rewards the lock-step vector gives it on the same per-env trajectories (an env's
// trajectory depends only on its seed and the actions sent to it).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <random>
#include <vector>

#include "learn/intrinsic/body_part_novelty.h"
#include "learn/intrinsic/disagreement.h"
#include "learn/intrinsic/episode_coverage.h"
#include "learn/intrinsic/icm.h"
#include "learn/intrinsic/regard_count.h"
#include "learn/intrinsic/reward.h"
#include "learn/vector_env.h"

namespace cradle::learn::intrinsic {
namespace {

constexpr std::uint64_t kSeed = 11;
constexpr int kActions = 2;

// A scripted infant: each step a hand (the sign of action 0) touches one of 12 geoms of its own
// (ids 100 x env id + k, so that envs never share a geom and the shared first-touch counts of
// body_part_novelty do not depend on the order of envs), each hand is in contact with 0-2 other
// geoms, the eyes count views as hand_regard does, and a 3-value state follows the actions.
// Episodes last 4-12 steps (drawn at reset), ending terminated or truncated.
class Toucher final : public envs::Env {
 public:
  explicit Toucher(int id)
      : id_(id),
        space_({{{"observation", Box::unbounded({3}, DType::kFloat64)}}}),
        action_(Box::uniform({kActions}, DType::kFloat64, -1, 1)),
        obs_(space_) {
    touches_[0] = info_.declare("right_hand_touches", envs::InfoType::kIntList);
    touches_[1] = info_.declare("left_hand_touches", envs::InfoType::kIntList);
    contacts_[0] = info_.declare("right_hand_contacts", envs::InfoType::kIntList, false);
    contacts_[1] = info_.declare("left_hand_contacts", envs::InfoType::kIntList, false);
    eyes_[0] = info_.declare("right_eye_either_hand", envs::InfoType::kInt);
    eyes_[1] = info_.declare("left_eye_either_hand", envs::InfoType::kInt);
  }
  const DictSpace& observation_space() const override { return space_; }
  const Box& action_space() const override { return action_; }
  const envs::ObservationBuffers& observation() const override { return obs_; }
  const envs::Info& info() const override { return info_; }

  void reset(std::optional<std::uint64_t> seed) override {
    if (seed) rng_.seed(*seed);
    info_.clear();
    info_.steps = steps_ = 0;
    length_ = 4 + static_cast<int>(rng_() % 9);
    for (double& x : obs_.f64(0)) x = uniform() - 0.5;
  }

  envs::StepResult step(std::span<const double> action) override {
    info_.steps = steps_++;
    // A first touch of one of this env's geoms by the hand the action picks.
    const int hand = action[0] > 0 ? 0 : 1;
    const int geom = 100 * id_ + static_cast<int>(rng_() % 12);
    std::vector<int>& touched = info_.list(touches_[hand]);
    if (std::find(touched.begin(), touched.end(), geom) == touched.end()) touched.push_back(geom);
    for (int h = 0; h < 2; ++h) {
      std::vector<int>& contacts = info_.list(contacts_[h]);
      contacts.clear();
      for (int k = static_cast<int>(rng_() % 3); k > 0; --k) {
        contacts.push_back(100 * id_ + 50 + static_cast<int>(rng_() % 6));
      }
    }
    info_.add(eyes_[0], action[1] > 0.3 ? 1 : 0);
    info_.add(eyes_[1], static_cast<double>(rng_() % 2));
    const std::span<double> x = obs_.f64(0);
    for (size_t k = 0; k < x.size(); ++k) {
      x[k] = 0.8 * x[k] + 0.5 * action[k % kActions] + 0.1 * (uniform() - 0.5);
    }
    const bool end = steps_ == length_;
    return {.reward = 0, .terminated = end && length_ % 2 == 0, .truncated = end && length_ % 2};
  }

 private:
  double uniform() { return static_cast<double>(rng_() >> 11) * 0x1.0p-53; }

  int id_;
  DictSpace space_;
  Box action_;
  envs::ObservationBuffers obs_;
  envs::Info info_;
  std::mt19937_64 rng_;
  int steps_ = 0, length_ = 0;
  int touches_[2], contacts_[2], eyes_[2];
};

std::vector<std::unique_ptr<envs::Env>> touchers(int n) {
  std::vector<std::unique_ptr<envs::Env>> list;
  for (int i = 0; i < n; ++i) list.push_back(std::make_unique<Toucher>(i));
  return list;
}

// The action env e takes at its k-th step: a fixed function of both, nothing else.
double action_of(int e, int k, int d) { return std::sin(0.7 * k + 1.3 * e + 2.1 * d); }

// Each env's intrinsic rewards, step by step.
using PerEnv = std::vector<std::vector<double>>;

// `steps` lock-step steps of n envs.
PerEnv lockstep(IntrinsicReward& reward, int n, int steps) {
  ThreadedVecEnv vec(touchers(n), 1);
  reward.bind(vec);
  vec.reset(kSeed);
  reward.reset(vec);
  PerEnv out(n);
  std::vector<double> actions(static_cast<size_t>(n) * kActions), rewards(n);
  for (int t = 0; t < steps; ++t) {
    for (int e = 0; e < n; ++e) {
      for (int d = 0; d < kActions; ++d) actions[e * kActions + d] = action_of(e, t, d);
    }
    vec.step(actions);
    std::fill(rewards.begin(), rewards.end(), 0.0);
    reward.compute(vec, actions, rewards);
    for (int e = 0; e < n; ++e) out[e].push_back(rewards[e]);
  }
  return out;
}

// The same n envs on an async vector: each round sends up to `batch` envs that still have steps
// to take, drawn at random (so envs run ahead of one another), and computes the reward over the
// batch that comes back (only those are in flight). With one thread a batch comes back in the
// order it was sent, so the slots of a batch are shuffled too.
PerEnv batched(IntrinsicReward& reward, int n, int batch, int threads, int steps,
               std::uint64_t order_seed) {
  AsyncVecEnv vec(touchers(n), batch, threads);
  reward.bind(vec);
  vec.reset(kSeed);
  reward.reset(vec);
  PerEnv out(n);
  std::mt19937_64 order(order_seed);
  std::vector<int> ids;
  std::vector<double> actions, rewards;
  for (;;) {
    ids.clear();
    for (int e = 0; e < n; ++e) {
      if (static_cast<int>(out[e].size()) < steps) ids.push_back(e);
    }
    if (ids.empty()) break;
    std::shuffle(ids.begin(), ids.end(), order);
    ids.resize(std::min<size_t>(ids.size(), batch));
    actions.clear();
    for (int e : ids) {
      for (int d = 0; d < kActions; ++d) actions.push_back(action_of(e, out[e].size(), d));
    }
    vec.send(actions, ids);
    const AsyncVecEnv::Batch b = vec.recv();
    EXPECT_EQ(b.size(), static_cast<int>(ids.size()));
    // The hook's actions in batch order.
    actions.clear();
    for (int e : b.ids) {
      for (int d = 0; d < kActions; ++d) actions.push_back(action_of(e, out[e].size(), d));
    }
    rewards.assign(b.size(), 0.0);
    reward.compute(BatchView(vec, b), actions, rewards);
    for (int j = 0; j < b.size(); ++j) out[b.ids[j]].push_back(rewards[j]);
  }
  return out;
}

double total(const PerEnv& rewards) {
  double sum = 0;
  for (const auto& env : rewards) {
    for (double r : env) sum += r;
  }
  return sum;
}

// Lock-step and batches of 2 and 3 of 5 envs (two threads, random batches) give every env the
// same rewards, exactly.
void expect_same_rewards_per_env(const std::function<std::unique_ptr<IntrinsicReward>()>& make) {
  constexpr int kEnvs = 5, kSteps = 60;
  const auto reference = make();
  const PerEnv expected = lockstep(*reference, kEnvs, kSteps);
  EXPECT_GT(total(expected), 0) << reference->name();
  for (int batch : {2, 3}) {
    for (std::uint64_t order_seed : {1, 2}) {
      const auto reward = make();
      EXPECT_EQ(batched(*reward, kEnvs, batch, 2, kSteps, order_seed), expected)
          << reward->name() << ", batches of " << batch << ", order " << order_seed;
    }
  }
}

TEST(AsyncIntrinsic, EpisodeCoverageGivesEachEnvItsLockStepRewards) {
  expect_same_rewards_per_env([] { return std::make_unique<EpisodeCoverage>(); });
}

TEST(AsyncIntrinsic, RegardCountGivesEachEnvItsLockStepRewards) {
  expect_same_rewards_per_env([] { return std::make_unique<RegardCount>(); });
}

TEST(AsyncIntrinsic, BodyPartNoveltyGivesEachEnvItsLockStepRewards) {
  // Without the hand balance, whose weights mix every env's counts (by design) into each bonus.
  expect_same_rewards_per_env(
      [] { return std::make_unique<BodyPartNovelty>(1.0, BodyPartNoveltyOptions{.balance = 0}); });
}

TEST(AsyncIntrinsic, FunctionRewardIsCalledWithTheEnvId) {
  expect_same_rewards_per_env([] {
    return std::make_unique<FunctionReward>(
        "id", [](int env, const envs::ObservationBuffers&, std::span<const double>,
                 const envs::Info&) { return 1.0 + env; });
  });
}

// The learned transition rewards pool every env's features into running statistics, so their
// rewards depend on the order of the rows; with whole-vector batches in shuffled slot order the
// statistics take the same rows each step, and each env's (s, a, s') must be its own.
LearnedOptions small_learned() {
  LearnedOptions o;
  o.hidden = 16;
  o.batch = 8;
  o.buffer = 4096;
  return o;
}

void expect_same_learned_rewards(const std::function<std::unique_ptr<LearnedReward>()>& make) {
  constexpr int kEnvs = 4, kSteps = 40;
  const auto reference = make();
  const PerEnv expected = lockstep(*reference, kEnvs, kSteps);
  const auto reward = make();
  const PerEnv got = batched(*reward, kEnvs, kEnvs, 1, kSteps, 3);
  for (int e = 0; e < kEnvs; ++e) {
    for (int t = 0; t < kSteps; ++t) {
      EXPECT_NEAR(got[e][t], expected[e][t], 1e-6 * std::max(1.0, std::abs(expected[e][t])))
          << reward->name() << " env " << e << " step " << t;
    }
  }
  EXPECT_GT(total(expected), 0);
  // Every transition sampled once (autoresets left out), in smaller batches too.
  const auto small = make();
  batched(*small, kEnvs, 3, 2, kSteps, 4);
  EXPECT_EQ(small->buffered(), reference->buffered());
  EXPECT_EQ(reward->buffered(), reference->buffered());
  EXPECT_LT(reference->buffered(), kEnvs * kSteps);
}

TEST(AsyncIntrinsic, IcmGivesEachEnvItsOwnTransitions) {
  expect_same_learned_rewards([] { return std::make_unique<Icm>(1.0, small_learned()); });
}

TEST(AsyncIntrinsic, DisagreementGivesEachEnvItsOwnTransitions) {
  expect_same_learned_rewards([] {
    return std::make_unique<Disagreement>(
        1.0, DisagreementOptions{.learned = small_learned(), .models = 3});
  });
}

}  // namespace
}  // namespace cradle::learn::intrinsic

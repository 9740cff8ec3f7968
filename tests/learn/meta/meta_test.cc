// SaMI learners: the SaNCE loss against a hand computation, the samplers' constraints, the
// encoder's momentum copy, acting vs training contexts, checkpoint round trips, Welch's test.
#include <gtest/gtest.h>
#include <torch/torch.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "core/error.h"
#include "learn/meta/context_encoder.h"
#include "learn/meta/context_sac.h"
#include "learn/meta/samplers.h"
#include "learn/meta/sance.h"
#include "learn/meta/trajectory_replay.h"
#include "train/sami/sami_experiment.h"

namespace cradle::learn::meta {
namespace {

double softplus(double x) { return std::log1p(std::exp(x)); }

TEST(Sance, EqualsHandComputationWithPaddedSteps) {
  // T = 2 steps, one positive and one negative trajectory, D = 2. Step 1 of the positive is
  // padding (mask 0); its embeddings are zero and give logits of 0.
  const torch::Tensor q = torch::tensor({1.0f, 0.0f, 5.0f, 5.0f}).reshape({2, 1, 2});
  const torch::Tensor kp = torch::tensor({3.0f, 4.0f, 7.0f, 7.0f}).reshape({2, 1, 2});
  const torch::Tensor kn = torch::tensor({0.0f, 2.0f, 3.0f, 4.0f}).reshape({2, 1, 2});
  const torch::Tensor mp = torch::tensor({1.0f, 0.0f}).reshape({2, 1});
  const torch::Tensor mn = torch::tensor({1.0f, 1.0f}).reshape({2, 1});
  // Queries (1, 0), (0, 0); keys+ (0.6, 0.8), (0, 0); keys- (0, 1), (0.6, 0.8); tau 0.1.
  // Positive logits: 6, 0, 0, 0. Negative logits: 0, 6, 0, 0.
  const double expected =
      (softplus(-6) + 3 * std::log(2.0)) / 4 + (3 * std::log(2.0) + softplus(6)) / 4;
  EXPECT_NEAR(sance_loss(q, kp, kn, mp, mn, 0.1).item<double>(), expected, 1e-6);
  EXPECT_NEAR(expected, 2.540958613408783, 1e-12);  // the same sum evaluated in Python
  // W = 2 I only rescales the keys, which normalisation undoes; a swap of axes changes it.
  EXPECT_NEAR(sance_loss(q, kp, kn, mp, mn, 0.1, 2 * torch::eye(2)).item<double>(), expected, 1e-6);
  const torch::Tensor swap = torch::tensor({0.0f, 1.0f, 1.0f, 0.0f}).reshape({2, 2});
  // Keys+ (0.8, 0.6); keys- (1, 0), (0.8, 0.6): positive logits 8, 0, 0, 0; negative 10, 8, 0, 0.
  const double swapped =
      (softplus(-8) + 3 * std::log(2.0)) / 4 + (softplus(10) + softplus(8) + 2 * std::log(2.0)) / 4;
  EXPECT_NEAR(sance_loss(q, kp, kn, mp, mn, 0.1, swap).item<double>(), swapped, 1e-5);
}

TEST(Sance, WeightIsClippedLambdaTimesReturnGap) {
  EXPECT_DOUBLE_EQ(sance_weight(0.01, 30, 10), 0.2);
  EXPECT_DOUBLE_EQ(sance_weight(0.01, 300, 10), 1.0);  // clipped at 1
  EXPECT_DOUBLE_EQ(sance_weight(0.01, 1, 5), 0.0);     // clipped at 0
  EXPECT_DOUBLE_EQ(sance_weight(0.1, 1, 0), 0.1);      // CCM's constants: w = lambda
}

// A replay of 3 envs whose trajectory k of env e has length 1 + k % 4 and constant reward
// 10 e + k (so its average return is 10 e + k).
TrajectoryReplay filled_replay() {
  TrajectoryReplay replay(3, 8, 4, 1, 1);
  for (int e = 0; e < 3; ++e) {
    for (int k = 0; k < 8; ++k) {
      const float o = 0;
      replay.begin(e, {&o, 1});
      for (int t = 0; t < 1 + k % 4; ++t) replay.add(e, {&o, 1}, 10.0 * e + k, {&o, 1});
      replay.finish(e, false);
    }
  }
  return replay;
}

TEST(Samplers, CountsAndMethodNames) {
  EXPECT_EQ(negative_count(16, 0.5), 8);
  EXPECT_EQ(negative_count(2, 0.9), 1);
  EXPECT_EQ(negative_count(3, 0.1), 1);
  EXPECT_EQ(method_contrast("SaCCM"), Contrast::kHalf);
  EXPECT_EQ(method_contrast("CCM"), Contrast::kEnvDiff);
  EXPECT_EQ(method_contrast("SaTESAC"), Contrast::kOne);
  EXPECT_EQ(method_contrast("SaCCMAll"), Contrast::kAll);
  EXPECT_EQ(method_contrast("TESAC"), Contrast::kNone);
  EXPECT_THROW(method_contrast("SaCCM2"), UserError);
}

std::set<int> envs_of(const TrajectoryReplay& r, const std::vector<long>& indices) {
  std::set<int> out;
  for (long i : indices) out.insert(r.env_of(i));
  return out;
}

double max_return(const TrajectoryReplay& r, const std::vector<long>& v) {
  double m = -1e9;
  for (long i : v) m = std::max(m, r.average_return(i));
  return m;
}
double min_return(const TrajectoryReplay& r, const std::vector<long>& v) {
  double m = 1e9;
  for (long i : v) m = std::min(m, r.average_return(i));
  return m;
}

TEST(Samplers, EachModeKeepsItsConstraints) {
  const TrajectoryReplay replay = filled_replay();
  for (int e = 0; e < 3; ++e) ASSERT_EQ(replay.stored(e), 8);
  EXPECT_DOUBLE_EQ(replay.average_return(replay.index(2, 5)), 25.0);
  Rng rng(3);
  for (int trial = 0; trial < 50; ++trial) {
    // env_diff: positives from one env, negatives from another; constant returns 1 and 0.
    ContrastSample s = sample_env_diff(replay, 10, 0.5, rng);
    ASSERT_EQ(s.positives.size(), 5u);
    ASSERT_EQ(s.negatives.size(), 5u);
    ASSERT_EQ(envs_of(replay, s.positives).size(), 1u);
    ASSERT_EQ(envs_of(replay, s.negatives).size(), 1u);
    ASSERT_NE(*envs_of(replay, s.positives).begin(), *envs_of(replay, s.negatives).begin());
    ASSERT_EQ(s.positive_return, 1.0);
    ASSERT_EQ(s.negative_return, 0.0);
    // one: one env, positives at least as good as every negative.
    s = sample_one(replay, 10, 0.3, rng);
    ASSERT_EQ(s.negatives.size(), 3u);
    ASSERT_EQ(s.positives.size(), 7u);
    std::vector<long> both = s.positives;
    both.insert(both.end(), s.negatives.begin(), s.negatives.end());
    ASSERT_EQ(envs_of(replay, both).size(), 1u);
    ASSERT_GE(min_return(replay, s.positives), max_return(replay, s.negatives));
    // half: positives from one env, each above the best negative; negatives the lowest half of
    // an even batch (so they cannot come only from the best env).
    s = sample_half(replay, 12, 0.5, rng);
    ASSERT_EQ(s.positives.size(), 6u);
    ASSERT_EQ(s.negatives.size(), 6u);
    ASSERT_EQ(envs_of(replay, s.positives).size(), 1u);
    ASSERT_GT(min_return(replay, s.positives), max_return(replay, s.negatives));
    ASSERT_TRUE(envs_of(replay, s.negatives).count(0));  // env 0 has the lowest returns
    // all: an even batch over all envs, sorted: top / bottom.
    s = sample_all(replay, 12, 0.5, rng);
    ASSERT_EQ(s.positives.size(), 6u);
    ASSERT_GE(min_return(replay, s.positives), max_return(replay, s.negatives));
    both = s.positives;
    both.insert(both.end(), s.negatives.begin(), s.negatives.end());
    ASSERT_EQ(envs_of(replay, both).size(), 3u);  // 4 from each env
  }
}

TEST(Samplers, HalfDrawsWithoutReplacementWhenEnoughBeatTheNegatives) {
  const TrajectoryReplay replay = filled_replay();
  Rng rng(5);
  for (int trial = 0; trial < 20; ++trial) {
    const ContrastSample s = sample_half(replay, 6, 0.5, rng);  // 3 positives, 3 negatives
    const std::set<long> unique(s.positives.begin(), s.positives.end());
    // Env 2's trajectories (returns 20..27) all beat env 0's; when env 2 is picked there are 8.
    if (*envs_of(replay, s.positives).begin() == 2) {
      ASSERT_EQ(unique.size(), 3u);
    }
  }
}

TEST(Replay, OpenSlotLeavesThePoolAndBatchesShiftActions) {
  TrajectoryReplay replay(1, 2, 3, 2, 1);
  const float o0[2] = {1, 2}, o1[2] = {3, 4}, o2[2] = {5, 6}, a0 = 0.5f, a1 = -0.5f;
  replay.begin(0, o0);
  replay.add(0, {&a0, 1}, 1.0, o1);
  replay.add(0, {&a1, 1}, 3.0, o2);
  replay.finish(0, true);
  EXPECT_EQ(replay.stored(0), 1);
  EXPECT_DOUBLE_EQ(replay.average_return(replay.index(0, 0)), 2.0);
  const auto batch = replay.gather({replay.index(0, 0)});
  EXPECT_EQ(batch.lengths[0].item<long>(), 2);
  EXPECT_FLOAT_EQ(batch.prev_actions[0][1][0].item<float>(), 0.5f);
  EXPECT_FLOAT_EQ(batch.prev_actions[0][0][0].item<float>(), 0.0f);
  EXPECT_FLOAT_EQ(batch.observations[0][2][1].item<float>(), 6.0f);
  EXPECT_FLOAT_EQ(batch.terminated[0][1].item<float>(), 1.0f);
  EXPECT_FLOAT_EQ(batch.valid[0][2].item<float>(), 0.0f);
  // Fill the ring; the slot being rewritten is out of the pool.
  replay.begin(0, o0);
  replay.add(0, {&a0, 1}, 1.0, o1);
  replay.finish(0, false);
  EXPECT_EQ(replay.stored(0), 2);
  replay.begin(0, o0);
  EXPECT_EQ(replay.stored(0), 1);
  EXPECT_EQ(replay.index(0, 0), 1);
}

SamiConfig tiny_config() {
  SamiConfig c;
  c.net_arch = {16, 16};
  c.lstm_hidden = 8;
  c.batch_size = 3;
  c.contrast_batch_size = 4;
  c.buffer_size = 8;
  c.adversarial_loss_coef = 1.0;
  return c;
}

// A replay of 3 envs filled by the learner's own stochastic acting on a toy signal, recording the
// contexts that acting produced.
struct Rollout {
  TrajectoryReplay replay{3, 8, 6, 2, 2};
  std::vector<torch::Tensor> contexts;  // per step [3, context]
};
Rollout roll(ContextSac& learner, int episodes) {
  Rollout r;
  Rng rng(1);
  for (int ep = 0; ep < episodes; ++ep) {
    ContextSac::Streams streams = learner.streams(3);
    torch::Tensor obs = torch::randn({3, 2});
    for (int e = 0; e < 3; ++e) r.replay.begin(e, {obs[e].data_ptr<float>(), 2});
    for (int t = 0; t < 6; ++t) {
      auto [a, c] = learner.act(obs, streams, false);
      r.contexts.push_back(c.clone());
      const torch::Tensor next = torch::randn({3, 2});
      for (int e = 0; e < 3; ++e) {
        r.replay.add(e, {a[e].data_ptr<float>(), 2}, rng.uniform() + e,
                     {next[e].data_ptr<float>(), 2});
      }
      obs = next;
    }
    for (int e = 0; e < 3; ++e) r.replay.finish(e, false);
  }
  return r;
}

TEST(ContextEncoder, ActingContextsEqualTrainingContexts) {
  ContextSac learner("SaCCM", 2, 2, tiny_config(), 11);
  const Rollout r = roll(learner, 1);
  // The training-time LSTM over the stored trajectories from a zero state.
  const auto batch =
      r.replay.gather({r.replay.index(0, 0), r.replay.index(1, 0), r.replay.index(2, 0)});
  torch::NoGradGuard no_grad;
  const torch::Tensor trained = learner.encoder()->forward(batch.encoder_input());  // [7, 3, 6]
  for (int t = 0; t < 6; ++t) {
    EXPECT_TRUE(torch::allclose(trained[t], r.contexts[t], 1e-5, 1e-6)) << "step " << t;
  }
}

TEST(ContextEncoder, TargetMovesByExactlyTau) {
  at::Generator g = at::make_generator<at::CPUGeneratorImpl>(3);
  EncoderPair pair(5, 8, 6, 1e-3, g);
  {
    torch::NoGradGuard no_grad;
    for (auto& p : pair.online->parameters()) p.add_(torch::randn(p.sizes(), g));
  }
  std::vector<torch::Tensor> before;
  for (auto& p : pair.target->parameters()) before.push_back(p.clone().to(torch::kFloat64));
  pair.update_target(0.05);
  const auto online = pair.online->parameters();
  const auto target = pair.target->parameters();
  ASSERT_EQ(target.size(), 4u);  // LSTM w_ih and w_hh (no biases), the head weight and bias
  for (size_t i = 0; i < target.size(); ++i) {
    const torch::Tensor expected = 0.05 * online[i].to(torch::kFloat64) + 0.95 * before[i];
    EXPECT_TRUE(torch::allclose(target[i].to(torch::kFloat64), expected, 0, 1e-6));
    EXPECT_FALSE(torch::allclose(target[i].to(torch::kFloat64), before[i]));
  }
}

TEST(ContextSac, UpdateMovesEncoderTargetByTauAndLearns) {
  for (const std::string_view method : method_names()) {
    ContextSac learner(std::string(method), 2, 2, tiny_config(), 4);
    const Rollout r = roll(learner, 3);
    std::vector<torch::Tensor> target_before;
    for (auto& p : learner.encoders().target->parameters()) target_before.push_back(p.clone());
    Rng rng(9);
    const ContextSac::Losses l = learner.update(r.replay, rng);
    EXPECT_TRUE(std::isfinite(l.critic)) << method;
    EXPECT_EQ(std::isnan(l.sance), method == "TESAC") << method;
    const auto online = learner.encoders().online->parameters();
    const auto target = learner.encoders().target->parameters();
    for (size_t i = 0; i < target.size(); ++i) {
      EXPECT_TRUE(
          torch::allclose(target[i], 0.05 * online[i] + 0.95 * target_before[i], 1e-5, 1e-6))
          << method;
    }
  }
}

std::string bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(ContextSac, CheckpointRoundTripsBitwise) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "cradle_meta_ckpt";
  std::filesystem::create_directories(dir);
  ContextSac a("SaCCM", 2, 2, tiny_config(), 1);
  const Rollout r = roll(a, 2);
  Rng rng(2);
  a.update(r.replay, rng);
  a.update(r.replay, rng);
  a.save(dir / "a.ckpt", 123);
  ContextSac b("SaCCM", 2, 2, tiny_config(), 99);
  EXPECT_EQ(b.load(dir / "a.ckpt"), 123);
  b.save(dir / "b.ckpt", 123);
  EXPECT_EQ(bytes(dir / "a.ckpt"), bytes(dir / "b.ckpt"));
  // The restored learner acts (and samples) exactly as the saved one.
  auto sa = a.streams(1), sb = b.streams(1);
  const torch::Tensor o = torch::ones({1, 2});
  EXPECT_TRUE(torch::equal(a.act(o, sa, false).first, b.act(o, sb, false).first));
  // Another method's checkpoint is refused with a one-line error.
  ContextSac c("CCM", 2, 2, tiny_config(), 1);
  EXPECT_THROW(c.load(dir / "a.ckpt"), UserError);
  std::filesystem::remove_all(dir);
}

TEST(SamiConfig, BadValuesAreUserErrors) {
  for (const auto& [name, value] : std::map<std::string, std::string>{{"neg_ratio", "1.5"},
                                                                      {"bogus", "1"},
                                                                      {"gamma", "x"},
                                                                      {"temperature", "0"},
                                                                      {"encoder_tau", "-1"}}) {
    SamiConfig c;
    EXPECT_THROW(apply_sami_hyperparameters(c, {{name, value}}), UserError) << name;
  }
  SamiConfig c;
  EXPECT_NO_THROW(apply_sami_hyperparameters(c, {{"adversarial_loss_coef", "0.1"}}));
  EXPECT_EQ(c.adversarial_loss_coef, 0.1);
}

TEST(Welch, MatchesScipyOnThePaperSeeds) {
  // scipy.stats.ttest_ind(a, b, equal_var=False) on tma_sami.md §8.1's per-seed train means.
  const train::Welch w =
      train::welch_test({0.940, 0.968, 0.942, 0.903, 0.922}, {0.455, 0.617, 0.565, 0.470, 0.410});
  EXPECT_NEAR(w.t, 10.92094914448999, 1e-9);
  EXPECT_NEAR(w.p, 0.00017260327729303908, 1e-10);
  const train::Welch x =
      train::welch_test({0.363, 0.386, 0.353, 0.358, 0.359}, {0.190, 0.196, 0.246, 0.179, 0.284});
  EXPECT_NEAR(x.t, 6.986614091141506, 1e-9);
  EXPECT_NEAR(x.p, 0.0012190198202428092, 1e-10);
}

}  // namespace
}  // namespace cradle::learn::meta

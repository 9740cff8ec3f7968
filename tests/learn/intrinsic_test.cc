// Intrinsic rewards: hand-computed values on hand-made observation buffers (a fake vector of
// envs), count fading and hand balance, learned rewards falling on what they have seen, the skin
// detector on rendered hand-regard views, parsing, and checkpoints.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "core/config.h"
#include "core/error.h"
#include "envs/babybench.h"
#include "learn/intrinsic/body_part_novelty.h"
#include "learn/intrinsic/disagreement.h"
#include "learn/intrinsic/episode_coverage.h"
#include "learn/intrinsic/features.h"
#include "learn/intrinsic/gaze_alignment.h"
#include "learn/intrinsic/hand_visibility.h"
#include "learn/intrinsic/icm.h"
#include "learn/intrinsic/regard_count.h"
#include "learn/intrinsic/reward.h"
#include "learn/intrinsic/rnd.h"
#include "learn/intrinsic/saliency.h"
#include "learn/intrinsic/touch_count.h"
#include "learn/vector_env.h"
#include "scene/compose.h"
#include "senses/vision.h"
#include "train/babybench_vector.h"

namespace cradle::learn::intrinsic {
namespace {

// An env whose observation and info the test writes directly.
class FakeEnv final : public envs::Env {
 public:
  FakeEnv(const DictSpace& space, const Box& action) : space_(space), action_(action), obs_(space) {
    info_.declare("right_hand_touches", envs::InfoType::kIntList);
    info_.declare("left_hand_touches", envs::InfoType::kIntList);
  }
  const DictSpace& observation_space() const override { return space_; }
  const Box& action_space() const override { return action_; }
  void reset(std::optional<std::uint64_t>) override {}
  envs::StepResult step(std::span<const double>) override { return {}; }
  const envs::ObservationBuffers& observation() const override { return obs_; }
  const envs::Info& info() const override { return info_; }

  envs::ObservationBuffers& obs() { return obs_; }
  envs::Info& mutable_info() { return info_; }

 private:
  DictSpace space_;
  Box action_;
  envs::ObservationBuffers obs_;
  envs::Info info_;
};

// A vector of FakeEnvs; step() changes nothing, the test sets buffers, infos and flags.
class FakeVec final : public VecEnv {
 public:
  FakeVec(int n, DictSpace space, int action_size = 2)
      : space_(std::move(space)),
        action_(Box::uniform({action_size}, DType::kFloat64, -1, 1)),
        rewards_(n, 0),
        terminated_(n, 0),
        truncated_(n, 0) {
    for (int i = 0; i < n; ++i) envs_.push_back(std::make_unique<FakeEnv>(space_, action_));
  }
  int num_envs() const override { return static_cast<int>(envs_.size()); }
  const DictSpace& observation_space() const override { return space_; }
  const Box& action_space() const override { return action_; }
  void reset(std::uint64_t) override {}
  void step(std::span<const double>) override {}
  const envs::ObservationBuffers& observation(int i) const override {
    return envs_[i]->observation();
  }
  std::span<const double> rewards() const override { return rewards_; }
  std::span<const std::uint8_t> terminated() const override { return terminated_; }
  std::span<const std::uint8_t> truncated() const override { return truncated_; }
  const envs::Info& info(int i) const override { return envs_[i]->info(); }
  envs::Env& env(int i) override { return *envs_[i]; }
  const envs::Env& env(int i) const override { return *envs_[i]; }

  envs::ObservationBuffers& obs(int i) { return envs_[i]->obs(); }
  envs::Info& info(int i) { return envs_[i]->mutable_info(); }
  // The self-touch list of env i's hand (0 right, 1 left).
  std::vector<int>& touches(int i, int hand) { return info(i).list(hand); }
  void set_done(int i, bool done) { truncated_[i] = done; }

 private:
  DictSpace space_;
  Box action_;
  std::vector<std::unique_ptr<FakeEnv>> envs_;
  std::vector<double> rewards_;
  std::vector<std::uint8_t> terminated_, truncated_;
};

DictSpace touch_space(int size) {
  return {{{"observation", Box::unbounded({4}, DType::kFloat64)},
           {"touch", Box::unbounded({size}, DType::kFloat32)}}};
}
DictSpace eye_space(int res) {
  return {{{"observation", Box::unbounded({4}, DType::kFloat64)},
           {"eye_left", Box::uniform({res, res, 3}, DType::kUInt8, 0, 255)},
           {"eye_right", Box::uniform({res, res, 3}, DType::kUInt8, 0, 255)}}};
}
DictSpace state_space(int size) {
  return {{{"observation", Box::unbounded({size}, DType::kFloat64)}}};
}

// One compute() over the vector with zero actions; returns the rewards.
std::vector<double> step(IntrinsicReward& reward, const VecEnv& vec) {
  std::vector<double> rewards(vec.num_envs(), 0);
  const std::vector<double> actions(vec.num_envs() * vec.action_space().size(), 0);
  reward.compute(vec, actions, rewards);
  return rewards;
}

void fill(std::span<std::uint8_t> rgb, std::uint8_t r, std::uint8_t g, std::uint8_t b) {
  for (size_t p = 0; p < rgb.size(); p += 3) {
    rgb[p] = r;
    rgb[p + 1] = g;
    rgb[p + 2] = b;
  }
}

// ---- touch_count ----

TEST(TouchCount, FractionOfEntriesAboveOneMicro) {
  const std::vector<float> touch = {0, 2e-6f, -1, 5, 1e-6f, 0.5f, 0, 0};
  EXPECT_DOUBLE_EQ(TouchCount::of(touch), 3.0 / 8);
  FakeVec vec(2, touch_space(8));
  std::copy(touch.begin(), touch.end(), vec.obs(0).f32(1).begin());
  TouchCount reward(2.0);
  reward.bind(vec);
  const auto r = step(reward, vec);
  EXPECT_DOUBLE_EQ(r[0], 2.0 * 3 / 8);
  EXPECT_DOUBLE_EQ(r[1], 0);
}

TEST(TouchCount, NeedsTouch) {
  FakeVec vec(1, eye_space(4));
  TouchCount reward;
  EXPECT_THROW(reward.bind(vec), UserError);
}

// ---- saliency ----

TEST(Saliency, ConstantImageIsZeroSinglePixelAndCheckerboardAsComputedByHand) {
  std::vector<double> gray;
  const int h = 8, w = 6;
  std::vector<std::uint8_t> img(h * w * 3);
  fill(img, 90, 40, 200);
  EXPECT_NEAR(Saliency::of(img, h, w, gray), 0, 1e-12);  // 4x - x - x - x - x rounds

  // One white interior pixel v on black: response 4v there and -v at its 4 neighbours.
  const double v = 0.2989 * 255 + 0.5870 * 255 + 0.1140 * 255;
  fill(img, 0, 0, 0);
  for (int c = 0; c < 3; ++c) img[(3 * w + 2) * 3 + c] = 255;
  EXPECT_NEAR(Saliency::of(img, h, w, gray), std::sqrt(20.0) * v / (h * w), 1e-9);

  // Checkerboard of v and 0: interior responses +-4v; reflect border: edge pixels +-3v
  // (the outside neighbour repeats the pixel), corners +-2v.
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < 3; ++c) img[(y * w + x) * 3 + c] = (x + y) % 2 ? 255 : 0;
    }
  }
  const double squares = 16.0 * (h - 2) * (w - 2) + 9.0 * 2 * ((h - 2) + (w - 2)) + 4.0 * 4;
  EXPECT_NEAR(Saliency::of(img, h, w, gray), std::sqrt(squares) * v / (h * w), 1e-9);
}

TEST(Saliency, SumsBothEyes) {
  FakeVec vec(1, eye_space(4));
  auto left = vec.obs(0).u8(1), right = vec.obs(0).u8(2);
  fill(left, 10, 10, 10);
  fill(right, 10, 10, 10);
  right[0] = 255;  // a corner pixel: +3 (255 - 10) x weights there, -1 at its two neighbours
  Saliency reward(0.5);
  reward.bind(vec);
  std::vector<double> gray;
  const double expected = Saliency::of(right, 4, 4, gray);
  EXPECT_GT(expected, 0);
  EXPECT_NEAR(step(reward, vec)[0], 0.5 * expected, 1e-12);
}

// ---- body_part_novelty ----

TEST(BodyPartNovelty, FirstTouchFullBonusRepeatsFadeHandsCountedApart) {
  FakeVec vec(2, touch_space(4));
  BodyPartNovelty reward(1.0, {.onset_weight = 0, .balance = 0});
  reward.bind(vec);
  reward.reset(vec);

  vec.touches(0, 0) = {5};
  auto r = step(reward, vec);
  EXPECT_DOUBLE_EQ(r[0], 1.0);
  EXPECT_DOUBLE_EQ(r[1], 0.0);
  EXPECT_DOUBLE_EQ(step(reward, vec)[0], 0.0);  // nothing new this step

  // New episodes of env 0: the same geom's first touch fades as 1/sqrt(1 + n).
  for (int episode = 1; episode <= 3; ++episode) {
    vec.set_done(0, true);
    step(reward, vec);  // the step that ends the episode
    vec.set_done(0, false);
    vec.touches(0, 0).clear();
    EXPECT_DOUBLE_EQ(step(reward, vec)[0], 0.0);  // the autoreset step
    vec.touches(0, 0) = {5};
    EXPECT_NEAR(step(reward, vec)[0], 1.0 / std::sqrt(1.0 + episode), 1e-12);
  }
  EXPECT_EQ(reward.first_touches(0, 5), 4);

  // The left hand's touches of the same geom are counted apart; in one step, two envs touching
  // the same geom both get the bonus of the counts before the step.
  vec.touches(0, 1) = {5, 7};
  vec.touches(1, 1) = {7};
  r = step(reward, vec);
  EXPECT_DOUBLE_EQ(r[0], 2.0);
  EXPECT_DOUBLE_EQ(r[1], 1.0);
  EXPECT_EQ(reward.first_touches(1, 7), 2);
  EXPECT_EQ(reward.first_touches(0, 7), 0);
  EXPECT_EQ(reward.distinct_geoms(0), 1);
  EXPECT_EQ(reward.distinct_geoms(1), 2);
}

TEST(BodyPartNovelty, HandWithFewerDistinctGeomsWeighsMore) {
  FakeVec vec(1, touch_space(4));
  BodyPartNovelty reward(1.0, {.onset_weight = 0, .balance = 1});
  reward.bind(vec);
  vec.touches(0, 0) = {1, 2, 3};
  EXPECT_DOUBLE_EQ(step(reward, vec)[0], 3.0);  // equal counts (0, 0): weights 1
  // Right 3 distinct, left 0: w_left = 2 (1 + 3) / (2 + 0 + 3), w_right = 2 (1 + 0) / 5.
  EXPECT_DOUBLE_EQ(reward.hand_weight(1), 1.6);
  EXPECT_DOUBLE_EQ(reward.hand_weight(0), 0.4);
  vec.touches(0, 1) = {9};
  vec.touches(0, 0).push_back(4);
  EXPECT_DOUBLE_EQ(step(reward, vec)[0], 1.6 + 0.4);
  BodyPartNovelty half(1.0, {.balance = 0.5});
  EXPECT_DOUBLE_EQ(half.hand_weight(0), 1.0);
}

TEST(BodyPartNovelty, SavesAndLoadsItsCounts) {
  FakeVec vec(1, touch_space(4));
  BodyPartNovelty a(1.0, {.balance = 0}), b(1.0, {.balance = 0});
  a.bind(vec);
  b.bind(vec);
  vec.touches(0, 0) = {3};
  step(a, vec);
  const auto dir = std::filesystem::temp_directory_path() / "cradle_intrinsic_bpn";
  std::filesystem::create_directories(dir);
  a.save(dir);
  b.load(dir);
  EXPECT_EQ(b.first_touches(0, 3), 1);
  EXPECT_EQ(b.distinct_geoms(0), 1);
  std::filesystem::remove_all(dir);
  EXPECT_THROW(b.load(dir), UserError);
}

// ---- learned rewards ----

LearnedOptions small_learned() {
  LearnedOptions o;
  o.hidden = 32;
  o.batch = 32;
  o.epochs = 4;
  o.learning_rate = 3e-3;
  return o;
}

// Env 0 shows `a` (slightly jittered so every feature has spread), env 1 shows `b`.
void show(FakeVec& vec, int env, const std::vector<double>& x) {
  std::copy(x.begin(), x.end(), vec.obs(env).f64(0).begin());
}

TEST(Rnd, RepeatedInputFallsNovelInputStaysHigh) {
  FakeVec vec(2, state_space(6));
  Rnd reward(1.0, {.learned = small_learned(), .out = 16});
  reward.bind(vec);
  const std::vector<double> a = {0.5, -1, 2, 0, 1, -0.5};
  auto jitter = [&](int k) {
    std::vector<double> x = a;
    for (size_t j = 0; j < x.size(); ++j) x[j] += 0.3 * std::sin(1.7 * k + 2.3 * j);
    return x;
  };
  show(vec, 0, a);
  show(vec, 1, jitter(0));
  step(reward, vec);
  const double before = reward.last_raw()[0];
  for (int round = 0; round < 40; ++round) {
    for (int k = 0; k < 16; ++k) {
      show(vec, 1, jitter(k));
      step(reward, vec);
    }
    reward.update();
  }
  step(reward, vec);
  const double after = reward.last_raw()[0];
  EXPECT_LT(after, 0.2 * before);
  // A state far from everything seen.
  show(vec, 1, {-3, 3, -2, 4, -3, 3});
  step(reward, vec);
  EXPECT_GT(reward.last_raw()[1], 5 * reward.last_raw()[0]);
}

// A deterministic two-state cycle s0 -> s1 -> s0 under a constant action, in env 0; env 1 shows
// jittered states so that features have spread.
template <typename Reward>
void expect_repeated_transition_falls(Reward& reward) {
  FakeVec vec(2, state_space(5), 3);
  reward.bind(vec);
  const std::vector<double> s0 = {1, 0, -1, 0.5, 0}, s1 = {0, 1, 0.5, -1, 1};
  std::vector<double> actions = {0.3, -0.2, 0.9, 0, 0, 0}, rewards(2);
  show(vec, 0, s0);
  show(vec, 1, s1);
  reward.reset(vec);
  auto run = [&](int steps) {
    double sum = 0;
    for (int t = 0; t < steps; ++t) {
      show(vec, 0, t % 2 ? s0 : s1);
      std::vector<double> x = t % 2 ? s1 : s0;
      for (size_t j = 0; j < x.size(); ++j) x[j] += 0.5 * std::sin(0.9 * t + 1.3 * j);
      show(vec, 1, x);
      reward.compute(vec, actions, rewards);
      sum += reward.last_raw()[0];
    }
    return sum / steps;
  };
  const double before = run(8);
  for (int round = 0; round < 40; ++round) {
    run(16);
    reward.update();
  }
  const double after = run(8);
  EXPECT_GT(before, 0);
  EXPECT_LT(after, 0.2 * before) << reward.name();
}

TEST(Icm, RepeatedDeterministicTransitionFalls) {
  Icm reward(1.0, small_learned());
  expect_repeated_transition_falls(reward);
}

TEST(Disagreement, RepeatedDeterministicTransitionFalls) {
  Disagreement reward(1.0, {.learned = small_learned(), .models = 4});
  expect_repeated_transition_falls(reward);
}

TEST(Icm, AutoresetStepIsNoTransition) {
  FakeVec vec(1, state_space(3));
  Icm reward(1.0, small_learned());
  reward.bind(vec);
  reward.reset(vec);
  step(reward, vec);
  EXPECT_EQ(reward.buffered(), 1);
  vec.set_done(0, true);
  step(reward, vec);  // ends the episode: still a transition
  vec.set_done(0, false);
  const auto r = step(reward, vec);  // the autoreset: none
  EXPECT_EQ(r[0], 0);
  EXPECT_EQ(reward.buffered(), 2);
  reward.update();
  EXPECT_EQ(reward.buffered(), 0);
}

TEST(Rnd, CheckpointRestoresTheSameRewards) {
  FakeVec vec(1, state_space(4));
  Rnd a(1.0, {.learned = small_learned()});
  LearnedOptions other = small_learned();
  other.seed = 99;  // different initial weights, replaced by the loaded ones
  Rnd b(1.0, {.learned = other});
  a.bind(vec);
  b.bind(vec);
  for (int t = 0; t < 20; ++t) {
    show(vec, 0, {std::sin(t * 1.0), std::cos(t * 0.7), 0.1 * t, 1});
    step(a, vec);
  }
  a.update();
  const auto dir = std::filesystem::temp_directory_path() / "cradle_intrinsic_rnd";
  std::filesystem::create_directories(dir);
  a.save(dir);
  b.load(dir);
  show(vec, 0, {0.3, -0.3, 1, 1});
  EXPECT_DOUBLE_EQ(step(a, vec)[0], step(b, vec)[0]);
  std::filesystem::remove_all(dir);
}

// Two identical learned rewards trained alike save byte-identical files (LibTorch's own optimiser
// format ordered the Adam states by tensor address), and a reward loaded from one continues
// exactly: the same rewards after one more update (the Adam moments were restored too).
template <typename Reward, typename Options>
void expect_identical_saves_and_exact_continuation(const Options& options, Options other) {
  FakeVec vec(1, state_space(4));
  Reward a(1.0, options), c(1.0, options), b(1.0, other);
  for (Reward* r : {&a, &b, &c}) r->bind(vec);
  auto run = [&](Reward& r, int from, int steps) {
    for (int t = from; t < from + steps; ++t) {
      show(vec, 0, {std::sin(t * 1.0), std::cos(t * 0.7), 0.1 * t, 1});
      step(r, vec);
    }
    r.update();
  };
  run(a, 0, 40);
  run(c, 0, 40);
  const auto dir = std::filesystem::temp_directory_path() /
                   ("cradle_intrinsic_bytes_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir / "a");
  std::filesystem::create_directories(dir / "c");
  a.save(dir / "a");
  c.save(dir / "c");
  const std::string pt = "intrinsic_" + std::string(a.name()) + ".pt";
  auto bytes = [](const std::filesystem::path& f) {
    std::ifstream in(f, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  EXPECT_FALSE(bytes(dir / "a" / pt).empty());
  EXPECT_EQ(bytes(dir / "a" / pt), bytes(dir / "c" / pt)) << a.name();
  b.load(dir / "a");
  // A resumed run starts new episodes: no transition spans the load.
  a.reset(vec);
  b.reset(vec);
  run(a, 40, 40);
  run(b, 40, 40);
  show(vec, 0, {0.3, -0.3, 1, 1});
  EXPECT_EQ(step(a, vec), step(b, vec)) << a.name();
  std::filesystem::remove_all(dir);
}

TEST(LearnedRewards, IdenticalRunsSaveIdenticalBytesAndContinueExactly) {
  LearnedOptions other = small_learned();
  other.seed = 99;  // different initial weights, replaced by the loaded ones
  expect_identical_saves_and_exact_continuation<Rnd>(RndOptions{.learned = small_learned()},
                                                     RndOptions{.learned = other});
  expect_identical_saves_and_exact_continuation<Icm>(small_learned(), other);
  expect_identical_saves_and_exact_continuation<Disagreement>(
      DisagreementOptions{.learned = small_learned(), .models = 3},
      DisagreementOptions{.learned = other, .models = 3});
}

TEST(Features, PoolsTouchAndImagesAndCopiesTheRest) {
  DictSpace space = {{{"observation", Box::unbounded({2}, DType::kFloat64)},
                      {"touch", Box::unbounded({8}, DType::kFloat32)},
                      {"eye_left", Box::uniform({4, 4, 3}, DType::kUInt8, 0, 255)}}};
  FakeVec vec(1, space);
  Features features(vec, {.image_cells = 2, .touch_chunks = 4});
  EXPECT_EQ(features.size(), 2 + 4 + 4);
  vec.obs(0).f64(0)[0] = 3;
  vec.obs(0).f64(0)[1] = -1;
  vec.obs(0).f32(1)[2] = 1;
  vec.obs(0).f32(1)[3] = -2;
  auto img = vec.obs(0).u8(2);
  fill(img, 0, 0, 0);
  for (int c = 0; c < 3; ++c) img[c] = 255;  // top-left pixel white: 1/4 of the first cell
  std::vector<float> out(features.size());
  features.extract(vec, 0, out);
  EXPECT_FLOAT_EQ(out[0], 3);
  EXPECT_FLOAT_EQ(out[1], -1);
  EXPECT_FLOAT_EQ(out[2], 0);
  EXPECT_FLOAT_EQ(out[3], std::log1p(3.0f));
  EXPECT_FLOAT_EQ(out[6], 0.25f);
  EXPECT_FLOAT_EQ(out[7], 0);
}

// ---- hand_visibility ----

TEST(HandVisibility, CentralSkinBlobScoresAboveCornerBlobAboveNone) {
  const int res = 32;
  std::vector<std::uint8_t> img(res * res * 3);
  HandVisibility reward;
  auto blob = [&](int y0, int x0) {
    fill(img, 205, 205, 205);  // the scene's grey wall
    for (int y = y0; y < y0 + 8; ++y) {
      for (int x = x0; x < x0 + 8; ++x) {
        img[(y * res + x) * 3] = 186;  // a rendered skin pixel
        img[(y * res + x) * 3 + 1] = 157;
        img[(y * res + x) * 3 + 2] = 98;
      }
    }
    return reward.of(img, res, res);
  };
  const double centre = blob(12, 12), corner = blob(0, 0);
  fill(img, 205, 205, 205);
  EXPECT_EQ(reward.of(img, res, res), 0);
  EXPECT_GT(corner, 0);
  EXPECT_GT(centre, 3 * corner);
  EXPECT_LT(centre, 1);
  EXPECT_TRUE(reward.skin(242, 204, 128));   // the material's own colour
  EXPECT_TRUE(reward.skin(60, 51, 32));      // in shade
  EXPECT_FALSE(reward.skin(20, 17, 10));     // too dark to judge
  EXPECT_FALSE(reward.skin(200, 40, 40));    // a red toy
  EXPECT_FALSE(reward.skin(230, 230, 220));  // a white one
  fill(img, 186, 157, 98);
  EXPECT_NEAR(reward.of(img, res, res), 1.0, 1e-12);
}

// The composed hand-regard scene: the right hand raised in front of the right eye scores higher
// than the default pose. The head is tilted 0.8 rad (at the config's 0.4 the raised hand only
// reaches the bottom rows of the view).
TEST(HandVisibility, RenderedHandInFrontOfTheEyeScoresAboveTheDefaultPose) {
  const auto model = scene::compile_scene(scene::compose_scene(
      load_config(std::filesystem::path(CRADLE_SOURCE_DIR) / "configs/config_handregard.yml")));
  const mjModel* m = model.get();
  mjData* d = mj_makeData(m);
  std::unique_ptr<senses::Eyes> eyes;
  try {
    eyes = std::make_unique<senses::Eyes>(m, 64);
  } catch (const std::exception& e) {
    mj_deleteData(d);
    GTEST_SKIP() << "no GL: " << e.what();
  }
  auto adr = [&](const char* joint) { return m->jnt_qposadr[mj_name2id(m, mjOBJ_JOINT, joint)]; };
  HandVisibility reward;
  std::vector<std::uint8_t> left(64 * 64 * 3), right(left.size());
  auto score = [&](double shoulder, double elbow) {
    mju_copy(d->qpos, m->qpos0, m->nq);
    d->qpos[adr("robot:head_tilt")] = 0.8;
    d->qpos[adr("robot:right_shoulder_ad_ab")] = shoulder * mjPI / 180;
    d->qpos[adr("robot:right_elbow")] = elbow * mjPI / 180;
    mj_forward(m, d);
    eyes->render(m, d, left, right);
    return std::pair{reward.of(left, 64, 64), reward.of(right, 64, 64)};
  };
  const auto [rest_left, rest_right] = score(0, 0);
  const auto [raised_left, raised_right] = score(-80, -100);
  EXPECT_LT(rest_left + rest_right, 0.01);
  EXPECT_GT(raised_right, 0.3);
  EXPECT_GT(raised_right, raised_left);
  mj_deleteData(d);
}

// ---- registry, composite, adapter ----

TEST(Registry, ParsesWeightsAndRejectsUnknownNames) {
  auto composite = parse_intrinsic("touch_count:0.5, body_part_novelty");
  ASSERT_EQ(composite->size(), 2);
  EXPECT_EQ(composite->term(0).name(), "touch_count");
  EXPECT_EQ(composite->term(0).scale(), 0.5);
  EXPECT_EQ(composite->term(1).name(), "body_part_novelty");
  EXPECT_EQ(composite->term(1).scale(), 1.0);
  EXPECT_EQ(composite->describe(), "touch_count:0.5,body_part_novelty:1");
  EXPECT_EQ(parse_intrinsic("")->size(), 0);
  try {
    parse_intrinsic("nonsense");
    FAIL() << "no error";
  } catch (const UserError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("nonsense"), std::string::npos);
    for (const std::string& name : intrinsic_names()) {
      EXPECT_NE(message.find(name), std::string::npos) << name;
    }
    EXPECT_EQ(message.find('\n'), std::string::npos);
  }
  EXPECT_THROW(parse_intrinsic("touch_count:x"), UserError);
  EXPECT_THROW(parse_intrinsic("touch_count:1e999"), UserError);
  EXPECT_THROW(parse_intrinsic("rnd,rnd:2"), UserError);
  for (const std::string& name : intrinsic_names()) EXPECT_EQ(make_intrinsic(name)->name(), name);
}

TEST(Registry, CompositeSumsItsTermsAndKeepsEach) {
  FakeVec vec(2, touch_space(4));
  vec.obs(0).f32(1)[0] = 1;
  auto composite = parse_intrinsic("touch_count:2");
  composite->add(std::make_unique<FunctionReward>(
      "env_index",
      [](int env, const envs::ObservationBuffers&, std::span<const double> action,
         const envs::Info&) { return env + 10 * action[1]; },
      3.0));
  composite->bind(vec);
  std::vector<double> actions = {0, 0.5, 0, 1}, rewards = {100, 200};
  composite->compute(vec, actions, rewards);
  EXPECT_DOUBLE_EQ(rewards[0], 100 + 2 * 0.25 + 3 * 5);
  EXPECT_DOUBLE_EQ(rewards[1], 200 + 0 + 3 * (1 + 10));
  EXPECT_DOUBLE_EQ(composite->last(0)[0], 0.5);
  EXPECT_DOUBLE_EQ(composite->last(1)[1], 33);
}

// ---- on the real self-touch env ----

TEST(BodyPartNovelty, OnTheSelfTouchEnvCountsWhatInfoRecords) {
  Config config =
      load_config(std::filesystem::path(CRADLE_SOURCE_DIR) / "configs/config_selftouch.yml");
  config.max_episode_steps = 60;
  auto vec = train::make_babybench_vec_env(config, 2, 1, /*training=*/false, 3);
  BodyPartNovelty reward;
  reward.bind(*vec);
  vec->reset(3);
  reward.reset(*vec);
  std::vector<double> actions(2 * vec->action_space().size()), rewards(2);
  long recorded = 0;
  for (int t = 0; t < 200; ++t) {
    for (size_t k = 0; k < actions.size(); ++k) actions[k] = std::sin(0.05 * t + k);
    vec->step(actions);
    std::fill(rewards.begin(), rewards.end(), 0);
    reward.compute(*vec, actions, rewards);
    for (int i = 0; i < 2; ++i) {
      EXPECT_GE(rewards[i], 0);
      EXPECT_TRUE(std::isfinite(rewards[i]));
      if (vec->terminated()[i] || vec->truncated()[i]) {
        const envs::Info& info = vec->info(i);
        recorded += info.list(info.find("right_hand_touches")).size() +
                    info.list(info.find("left_hand_touches")).size();
      }
    }
  }
  long counted = 0;
  for (int h = 0; h < 2; ++h) {
    for (int g = 0; g < 200; ++g) counted += reward.first_touches(h, g);
  }
  // 200 steps of 60-step episodes: three finished episodes per env, a partial fourth.
  EXPECT_GE(counted, recorded);
}

// ---- episode_coverage ----

TEST(EpisodeCoverage, PaysEachNewGeomOnceAnEpisodeAndEveryEpisodeAgain) {
  FakeVec vec(2, touch_space(4));
  EpisodeCoverage reward(2.0);
  reward.bind(vec);
  reward.reset(vec);
  for (int episode = 0; episode < 3; ++episode) {
    vec.touches(0, 0) = {5};
    vec.touches(0, 1) = {5, 9};  // the other hand's touches of the same geom count apart
    auto r = step(reward, vec);
    EXPECT_DOUBLE_EQ(r[0], 2.0 * 3 / 68);  // no fading over episodes
    EXPECT_DOUBLE_EQ(r[1], 0.0);
    EXPECT_DOUBLE_EQ(step(reward, vec)[0], 0.0);  // nothing new this step
    vec.touches(0, 0) = {5, 11};
    EXPECT_DOUBLE_EQ(step(reward, vec)[0], 2.0 / 68);
    // The episode ends; the autoreset step's empty lists pay nothing.
    vec.set_done(0, true);
    step(reward, vec);
    vec.set_done(0, false);
    vec.touches(0, 0).clear();
    vec.touches(0, 1).clear();
    EXPECT_DOUBLE_EQ(step(reward, vec)[0], 0.0);
  }
}

TEST(EpisodeCoverage, EpisodeSumIsTheSelfTouchScoreOnTheRealEnv) {
  Config config =
      load_config(std::filesystem::path(CRADLE_SOURCE_DIR) / "configs/config_selftouch.yml");
  config.max_episode_steps = 80;
  auto vec = train::make_babybench_vec_env(config, 1, 1, /*training=*/false, 5);
  EpisodeCoverage reward;
  reward.bind(*vec);
  vec->reset(5);
  reward.reset(*vec);
  std::vector<double> actions(vec->action_space().size()), rewards(1);
  double episode_sum = 0;
  int episodes = 0;
  for (int t = 0; t < 160 && episodes < 1; ++t) {
    for (size_t k = 0; k < actions.size(); ++k) actions[k] = std::sin(0.07 * t + 1.3 * k);
    vec->step(actions);
    rewards[0] = 0;
    reward.compute(*vec, actions, rewards);
    episode_sum += rewards[0];
    if (vec->terminated()[0] || vec->truncated()[0]) {
      const envs::Info& info = vec->info(0);
      const double score = (info.list(info.find("right_hand_touches")).size() +
                            info.list(info.find("left_hand_touches")).size()) /
                           68.0;
      EXPECT_NEAR(episode_sum, score, 1e-12);
      ++episodes;
    }
  }
  EXPECT_EQ(episodes, 1);

  // Without a self-touch behaviour there is nothing to pay for: a one-line error.
  config.behavior = Behavior::kNone;
  auto plain = train::make_babybench_vec_env(config, 1, 1, /*training=*/false, 5);
  EXPECT_THROW(reward.bind(*plain), UserError);
}

TEST(RegardCount, EpisodeSumIsTheEitherHandCountOnTheRealEnv) {
  Config config =
      load_config(std::filesystem::path(CRADLE_SOURCE_DIR) / "configs/config_handregard.yml");
  config.vision_active = false;  // the counters come from geometry, not from the images
  config.max_episode_steps = 60;
  config.hand_regard_half_angle = 60;  // wide cones, so that some steps count
  auto vec = train::make_babybench_vec_env(config, 1, 1, /*training=*/false, 2);
  RegardCount reward(3.0);
  reward.bind(*vec);
  vec->reset(2);
  reward.reset(*vec);
  std::vector<double> actions(vec->action_space().size()), rewards(1);
  double episode_sum = 0, autoreset_reward = -1;
  int episodes = 0;
  bool ended = false;
  for (int t = 0; t < 70; ++t) {
    for (size_t k = 0; k < actions.size(); ++k) actions[k] = std::sin(0.1 * t + 0.7 * k);
    vec->step(actions);
    rewards[0] = 0;
    reward.compute(*vec, actions, rewards);
    if (ended) autoreset_reward = rewards[0];
    ended = false;
    episode_sum += rewards[0];
    if (vec->terminated()[0] || vec->truncated()[0]) {
      const envs::Info& info = vec->info(0);
      const double either = info.number(info.find("right_eye_either_hand")) +
                            info.number(info.find("left_eye_either_hand"));
      EXPECT_GT(either, 0);
      EXPECT_NEAR(episode_sum, 3.0 * either / 2, 1e-12);
      ++episodes;
      ended = true;
      episode_sum = 0;
    }
  }
  EXPECT_EQ(episodes, 1);
  EXPECT_EQ(autoreset_reward, 0.0);  // the autoreset step is no transition

  config.behavior = Behavior::kNone;
  auto plain = train::make_babybench_vec_env(config, 1, 1, /*training=*/false, 2);
  EXPECT_THROW(reward.bind(*plain), UserError);
}

// The gaze angles are the ones the counters threshold: an eye's either-hand counter grows at a
// step exactly when its angle is inside the cone; the reward is the formula on those angles.
TEST(GazeAlignment, AnglesAgreeWithTheCountersAndTheRewardIsTheFormula) {
  Config config =
      load_config(std::filesystem::path(CRADLE_SOURCE_DIR) / "configs/config_handregard.yml");
  config.vision_active = false;
  config.max_episode_steps = 200;
  config.hand_regard_half_angle = 60;  // wide cones, so that some steps count and some do not
  auto vec = train::make_babybench_vec_env(config, 1, 1, /*training=*/false, 2);
  GazeAlignment reward(2.0);
  reward.bind(*vec);
  vec->reset(2);
  const envs::Info& info = vec->info(0);
  const int angle[2] = {info.find("right_eye_gaze_angle"), info.find("left_eye_gaze_angle")};
  const int either[2] = {info.find("right_eye_either_hand"), info.find("left_eye_either_hand")};
  EXPECT_EQ(info.to_json().count("right_eye_gaze_angle"), 0u);  // a learner's signal only
  std::vector<double> actions(vec->action_space().size()), rewards(1);
  double previous[2] = {0, 0};
  int inside = 0, outside = 0;
  for (int t = 0; t < 150; ++t) {
    for (size_t k = 0; k < actions.size(); ++k) actions[k] = std::sin(0.05 * t + 0.7 * k);
    vec->step(actions);
    rewards[0] = 0.25;
    reward.compute(*vec, actions, rewards);
    double expected = 0;
    for (int eye = 0; eye < 2; ++eye) {
      const double theta = info.number(angle[eye]);
      ASSERT_GE(theta, 0);
      ASSERT_LE(theta, 180);
      const bool counted = info.number(either[eye]) > previous[eye];
      EXPECT_EQ(counted, theta < 60) << "step " << t << " eye " << eye << " angle " << theta;
      (counted ? inside : outside) += 1;
      previous[eye] = info.number(either[eye]);
      expected += (1 - theta / 180) * (1 - theta / 180);
    }
    EXPECT_NEAR(rewards[0], 0.25 + 2.0 * expected / 2, 1e-12);
  }
  EXPECT_GT(inside, 0);
  EXPECT_GT(outside, 0);

  config.behavior = Behavior::kNone;
  auto plain = train::make_babybench_vec_env(config, 1, 1, /*training=*/false, 2);
  EXPECT_THROW(reward.bind(*plain), UserError);
}

}  // namespace
}  // namespace cradle::learn::intrinsic

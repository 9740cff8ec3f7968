// The threaded vector env on the self-touch config: spaces, next-step autoreset, determinism
// across thread counts, independent envs, gathers and the shared training log.
#include "learn/vector_env.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/jsonl.h"
#include "core/rng.h"
#include "envs/babybench.h"
#include "train/babybench_vector.h"
#include "vector_snapshot.h"

namespace cradle::learn {
namespace {

namespace fs = std::filesystem;

Config self_touch(int max_steps) {
  Config config = load_config(fs::path(CRADLE_SOURCE_DIR) / "configs" / "config_selftouch.yml");
  config.max_episode_steps = max_steps;
  return config;
}

// A vector over `assets` built the way make_babybench_vec_env builds one.
std::unique_ptr<ThreadedVecEnv> vector_of(std::shared_ptr<const envs::BabyBenchAssets> assets,
                                          int n, int threads, std::uint64_t seed) {
  std::vector<std::unique_ptr<envs::Env>> list;
  for (int i = 0; i < n; ++i) {
    list.push_back(std::make_unique<envs::BabyBenchEnv>(assets, ThreadedVecEnv::env_seed(seed, i)));
  }
  return std::make_unique<ThreadedVecEnv>(std::move(list), threads);
}

bool same_observation(const envs::ObservationBuffers& a, const envs::ObservationBuffers& b) {
  if (a.count() != b.count()) return false;
  for (int k = 0; k < a.count(); ++k) {
    if (!std::ranges::equal(a.bytes(k), b.bytes(k))) return false;
  }
  return true;
}

using test::random_actions;
using test::snapshot;

TEST(ThreadedVecEnv, SpacesAreOneEnvs) {
  const auto assets = envs::make_assets(self_touch(20));
  const envs::BabyBenchEnv one(assets);
  const auto vec = vector_of(assets, 3, 2, 0);
  EXPECT_EQ(vec->num_envs(), 3);
  EXPECT_EQ(vec->threads(), 2);
  EXPECT_EQ(vec->observation_space(), one.observation_space());
  EXPECT_EQ(vec->action_space(), one.action_space());
  EXPECT_EQ(vector_of(assets, 2, 8, 0)->threads(), 2);  // never more threads than envs
  EXPECT_EQ(vector_of(assets, 2, 1, 0)->threads(), 1);
}

TEST(ThreadedVecEnv, RejectsMismatchedInput) {
  const auto assets = envs::make_assets(self_touch(20));
  EXPECT_THROW(ThreadedVecEnv({}, 1), std::invalid_argument);
  Config other = self_touch(20);
  other.vestibular_active = false;  // another observation space
  std::vector<std::unique_ptr<envs::Env>> list;
  list.push_back(std::make_unique<envs::BabyBenchEnv>(assets));
  list.push_back(std::make_unique<envs::BabyBenchEnv>(envs::make_assets(other)));
  EXPECT_THROW(ThreadedVecEnv(std::move(list), 1), std::invalid_argument);

  const auto vec = vector_of(assets, 2, 2, 0);
  vec->reset(0);
  std::vector<double> short_actions(vec->action_space().size());
  EXPECT_THROW(vec->step(short_actions), std::invalid_argument);
}

TEST(ThreadedVecEnv, ResetSeedsEachEnvWithItsDerivedSeed) {
  const auto assets = envs::make_assets(self_touch(20));
  const auto vec = vector_of(assets, 3, 2, 0);
  vec->reset(42);
  for (int i = 0; i < 3; ++i) {
    envs::BabyBenchEnv ref(assets);
    ref.reset(ThreadedVecEnv::env_seed(42, i));
    EXPECT_TRUE(same_observation(vec->observation(i), ref.observation())) << i;
  }
  // Different seeds: different random starts.
  EXPECT_FALSE(same_observation(vec->observation(0), vec->observation(1)));
  EXPECT_FALSE(same_observation(vec->observation(1), vec->observation(2)));
  EXPECT_NE(ThreadedVecEnv::env_seed(42, 0), ThreadedVecEnv::env_seed(43, 0));
}

TEST(ThreadedVecEnv, NextStepAutoreset) {
  const int max_steps = 20;
  const auto assets = envs::make_assets(self_touch(max_steps));
  const auto vec = vector_of(assets, 3, 2, 7);
  vec->reset(7);
  Rng rng(1);
  std::vector<double> actions(3 * vec->action_space().size());
  for (int t = 1; t <= max_steps; ++t) {
    random_actions(vec->action_space(), rng, actions);
    vec->step(actions);
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(vec->truncated()[i], t == max_steps) << t;
      EXPECT_EQ(vec->terminated()[i], 0);
      EXPECT_EQ(vec->info(i).steps, t - 1);
    }
  }
  // The call after the truncation resets instead of stepping.
  random_actions(vec->action_space(), rng, actions);
  vec->step(actions);
  for (int i = 0; i < 3; ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(vec->rewards()[i], 0.0);
    EXPECT_EQ(vec->truncated()[i], 0);
    EXPECT_EQ(vec->terminated()[i], 0);
    EXPECT_EQ(vec->info(i).steps, 0);
    EXPECT_TRUE(vec->info(i).list(vec->info(i).find("right_hand_touches")).empty());
    EXPECT_EQ(static_cast<envs::BabyBenchEnv&>(vec->env(i)).episode_steps(), 0);
    // A new episode's first observation: the env's second reset from its derived seed.
    envs::BabyBenchEnv ref(assets);
    ref.reset(ThreadedVecEnv::env_seed(7, i));
    ref.reset();
    EXPECT_TRUE(same_observation(vec->observation(i), ref.observation()));
  }
  // And the next call steps again.
  random_actions(vec->action_space(), rng, actions);
  vec->step(actions);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(static_cast<envs::BabyBenchEnv&>(vec->env(i)).episode_steps(), 1);
    EXPECT_EQ(vec->truncated()[i], 0);
  }
}

// reset_ended (SB3's same-step autoreset): the ending call's flags stay, the env starts its next
// episode at once (the same observation next-step autoreset gives one call later), and the next
// call steps it.
TEST(ThreadedVecEnv, ResetEndedResetsInTheSameStep) {
  const int max_steps = 3;
  const auto assets = envs::make_assets(self_touch(max_steps));
  const auto vec = vector_of(assets, 2, 2, 7);
  vec->reset(7);
  std::vector<double> actions(2 * vec->action_space().size(), 0.0);
  for (int t = 1; t <= max_steps; ++t) vec->step(actions);
  vec->reset_ended();
  for (int i = 0; i < 2; ++i) {
    SCOPED_TRACE(i);
    EXPECT_EQ(vec->truncated()[i], 1);
    EXPECT_EQ(static_cast<envs::BabyBenchEnv&>(vec->env(i)).episode_steps(), 0);
    envs::BabyBenchEnv ref(assets);
    ref.reset(ThreadedVecEnv::env_seed(7, i));
    ref.reset();
    EXPECT_TRUE(same_observation(vec->observation(i), ref.observation()));
  }
  vec->step(actions);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(static_cast<envs::BabyBenchEnv&>(vec->env(i)).episode_steps(), 1);
    EXPECT_EQ(vec->truncated()[i], 0);
  }
}

TEST(ThreadedVecEnv, SameBatchesForAnyThreadCount) {
  const Config config = self_touch(20);
  const auto one = train::make_babybench_vec_env(config, 3, 1, /*training=*/false, 5);
  const auto two = train::make_babybench_vec_env(config, 3, 2, /*training=*/false, 5);
  ASSERT_EQ(one->threads(), 1);
  ASSERT_EQ(two->threads(), 2);
  one->reset(11);
  two->reset(11);
  EXPECT_EQ(snapshot(*one), snapshot(*two));
  Rng rng(3);
  std::vector<double> actions(3 * one->action_space().size());
  int truncations = 0;
  for (int t = 0; t < 100; ++t) {
    random_actions(one->action_space(), rng, actions);
    one->step(actions);
    two->step(actions);
    ASSERT_EQ(snapshot(*one), snapshot(*two)) << "step " << t;
    truncations += one->truncated()[0];
  }
  EXPECT_EQ(truncations, 4);  // the run went through autoresets
  // Different envs of one vector went different ways.
  EXPECT_FALSE(same_observation(one->observation(0), one->observation(1)));
}

TEST(ThreadedVecEnv, GatherCopiesEveryEnv) {
  const auto assets = envs::make_assets(self_touch(20));
  const auto vec = vector_of(assets, 3, 2, 0);
  vec->reset(1);
  for (int k = 0; k < static_cast<int>(vec->observation_space().entries.size()); ++k) {
    const int size = vec->key_size(k);
    std::vector<float> out(3 * size);
    vec->gather(k, out);
    for (int i = 0; i < 3; ++i) {
      const envs::ObservationBuffers& obs = vec->observation(i);
      for (int j = 0; j < size; ++j) {
        const DType dtype = vec->observation_space().entries[k].second.dtype;
        const float expected = dtype == DType::kFloat64   ? static_cast<float>(obs.f64(k)[j])
                               : dtype == DType::kFloat32 ? obs.f32(k)[j]
                                                          : obs.u8(k)[j];
        ASSERT_EQ(out[i * size + j], expected) << k << " " << i << " " << j;
      }
    }
    std::vector<float> wrong(size);
    EXPECT_THROW(vec->gather(k, wrong), std::invalid_argument);
    std::vector<std::uint8_t> bytes(3 * size);
    EXPECT_THROW(vec->gather(k, bytes), std::invalid_argument);  // no uint8 keys here
  }
}

TEST(ThreadedVecEnv, TrainingWritesOneSharedLog) {
  const fs::path dir = fs::temp_directory_path() / ("cradle_vec_log_" + std::to_string(getpid()));
  fs::remove_all(dir);
  Config config = self_touch(10);
  config.save_dir = dir.string();
  {
    const auto vec = train::make_babybench_vec_env(config, 3, 2, /*training=*/true, 9);
    EXPECT_TRUE(fs::exists(dir / "scene" / "scene.xml"));
    EXPECT_TRUE(fs::is_directory(dir / "videos"));
    vec->reset(9);
    std::vector<double> actions(3 * vec->action_space().size(), 0.1);
    // 10 steps, autoreset, 10 steps, autoreset, 3 steps.
    for (int t = 0; t < 25; ++t) vec->step(actions);
  }  // destroying the envs records their partial episodes
  const auto entries = read_jsonl(dir / "logs" / "training.jsonl");
  ASSERT_EQ(entries.size(), 3u * 4);
  std::vector<int> steps;
  for (const auto& e : entries) steps.push_back(e["steps"]);
  std::ranges::sort(steps);
  EXPECT_EQ(steps, (std::vector<int>{0, 0, 0, 3, 3, 3, 10, 10, 10, 10, 10, 10}));
  fs::remove_all(dir);
}

}  // namespace
// A vector that cannot fit in memory is refused before any env is built, in one line saying how
// many envs fit: that count's envs fit in 80 % of the physical memory and one more does not.
TEST(ThreadedVecEnv, VectorBeyondMemoryIsRefusedWithTheCountThatFits) {
  const int too_many = 10'000'000;  // at >= 1 MB of MuJoCo data each, beyond any machine
  try {
    train::make_babybench_vec_env(self_touch(20), too_many, 1, /*training=*/false, 0);
    FAIL() << "no error for " << too_many << " envs";
  } catch (const UserError& e) {
    const std::string message = e.what();
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    double total_gb = 0, each_mb = 0, physical_gb = 0;
    int fit = 0, asked = 0;
    ASSERT_EQ(std::sscanf(message.c_str(),
                          "%d envs need about %lf GB (%lf MB each), more than 80%% of this "
                          "machine's %lf GB of memory; use at most %d envs",
                          &asked, &total_gb, &each_mb, &physical_gb, &fit),
              5)
        << message;
    EXPECT_EQ(asked, too_many);
    const double physical_mb = static_cast<double>(sysconf(_SC_PHYS_PAGES)) *
                               static_cast<double>(sysconf(_SC_PAGE_SIZE)) / 1e6;
    EXPECT_NEAR(physical_gb * 1e3, physical_mb, 100);
    EXPECT_GE(fit, 1);
    // The printed sizes are rounded (MB to 1, GB to 0.1): allow that much.
    EXPECT_LE(fit * (each_mb - 0.5), 0.8 * physical_mb) << message;
    EXPECT_GT((fit + 1) * (each_mb + 0.5), 0.8 * physical_mb) << message;
  }
}

}  // namespace cradle::learn

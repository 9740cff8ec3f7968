// The training log written by an env in training mode: entries per finished episode, the first
// 0-step entry, the last partial episode on close, append-only reload.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "core/jsonl.h"
#include "envs/babybench.h"

namespace cradle::envs {
namespace {

namespace fs = std::filesystem;

TEST(TrainingLog, EpisodesAreAppendedAndReloaded) {
  const fs::path dir = fs::temp_directory_path() / ("cradle_log_" + std::to_string(getpid()));
  fs::remove_all(dir);
  Config config = load_config(fs::path(CRADLE_SOURCE_DIR) / "configs" / "config_selftouch.yml");
  config.save_dir = dir.string();
  config.max_episode_steps = 30;
  config.save_logs_every = 2;
  {
    auto env = make_env(config, /*training=*/true, 3);
    EXPECT_TRUE(fs::exists(dir / "scene.xml"));
    env->reset(3);
    std::vector<double> action(env->action_space().size(), 0.2);
    for (int t = 0; t < 75; ++t) {
      if (env->step(action).truncated) env->reset();
    }
    env->close();  // 2 full episodes, then 15 steps of a third
  }
  const auto entries = read_jsonl(dir / "logs" / "training.jsonl");
  ASSERT_EQ(entries.size(), 4u);
  EXPECT_EQ(entries[0]["steps"], 0);
  EXPECT_EQ(entries[1]["steps"], 30);
  EXPECT_EQ(entries[2]["steps"], 30);
  EXPECT_EQ(entries[3]["steps"], 15);
  for (const auto& e : entries) {
    EXPECT_TRUE(e.contains("right_hand_touches"));
    EXPECT_TRUE(e.contains("left_hand_touches"));
    EXPECT_TRUE(e.contains("wall_time"));
    const double score = e["score"];
    EXPECT_DOUBLE_EQ(score,
                     (e["right_hand_touches"].size() + e["left_hand_touches"].size()) / 68.0);
  }
  fs::remove_all(dir);
}

TEST(TrainingLog, EpisodeScores) {
  Info info;
  info.right_hand_touches = {1, 2, 3};
  info.left_hand_touches = {4};
  EXPECT_DOUBLE_EQ(episode_score(Behavior::kSelfTouch, info, 10), 4.0 / 68);
  info.hand_regard = {10, 0, 10, 20};
  EXPECT_DOUBLE_EQ(episode_score(Behavior::kHandRegard, info, 100), 40.0 / 400);
  EXPECT_TRUE(std::isnan(episode_score(Behavior::kNone, info, 100)));
}

}  // namespace
}  // namespace cradle::envs

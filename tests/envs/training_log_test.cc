// The training log written by an env in training mode: entries per finished episode, the first
// 0-step entry, the last partial episode on close, append-only reload.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <stdexcept>

#include "core/jsonl.h"
#include "envs/babybench.h"
#include "envs/hand_regard.h"
#include "envs/self_touch.h"

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
    // The scene and its textures in scene/, nothing of it at the top.
    EXPECT_TRUE(fs::exists(dir / "scene" / "scene.xml"));
    EXPECT_TRUE(fs::exists(dir / "scene" / "tex_head_default_right.png"));
    EXPECT_FALSE(fs::exists(dir / "scene.xml"));
    for (const auto& entry : fs::directory_iterator(dir)) {
      EXPECT_NE(entry.path().extension(), ".png") << entry.path();
    }
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

// Tasks own their scores: self-touch (|right| + |left|) / 68, hand regard the mean fraction of
// steps each eye-hand pair was in view, none measures nothing.
TEST(TrainingLog, EpisodeScoresAreTheTasks) {
  Config config = load_config(fs::path(CRADLE_SOURCE_DIR) / "configs" / "config_selftouch.yml");
  const auto selftouch = make_assets(config);
  SelfTouch touch(selftouch->model.get());
  Info info;
  touch.declare(info);
  info.list(info.find("right_hand_touches")) = {1, 2, 3};
  info.list(info.find("left_hand_touches")) = {4};
  EXPECT_DOUBLE_EQ(touch.score(info, 10), 4.0 / 68);

  config = load_config(fs::path(CRADLE_SOURCE_DIR) / "configs" / "config_handregard.yml");
  config.vision_active = false;
  const auto handregard = make_assets(config);
  HandRegard regard(handregard->model.get(), 15, false);
  Info seen;
  regard.declare(seen);
  const char* pairs[4] = {"right_eye_right_hand", "right_eye_left_hand", "left_eye_right_hand",
                          "left_eye_left_hand"};
  const double steps_in_view[4] = {10, 0, 10, 20};
  for (int k = 0; k < 4; ++k) seen.set(seen.find(pairs[k]), steps_in_view[k]);
  EXPECT_DOUBLE_EQ(regard.score(seen, 100), 40.0 / 400);
  EXPECT_DOUBLE_EQ(regard.score(seen, 0), 0);

  config.behavior = Behavior::kNone;
  EXPECT_TRUE(std::isnan(make_behaviour(config, handregard->model.get())->score(seen, 100)));
}

// The open info: declared keys in order, typed JSON, unpublished keys kept out, clear() keeps keys.
TEST(Info, DeclaredKeysConvertGenerically) {
  Info info;
  const int flag = info.declare("is_success", InfoType::kBool);
  const int count = info.declare("count", InfoType::kInt);
  const int list = info.declare("touches", InfoType::kIntList);
  const int hidden = info.declare("contacts", InfoType::kIntList, /*published=*/false);
  EXPECT_THROW(info.declare("count", InfoType::kReal), std::logic_error);
  EXPECT_EQ(info.find("touches"), list);
  EXPECT_EQ(info.find("absent"), -1);
  info.set(flag, 1);
  info.add(count, 2);
  info.add(count, 3);
  info.list(list) = {7, 8};
  info.list(hidden) = {9};
  info.steps = 4;
  const nlohmann::json j = info.to_json();
  EXPECT_EQ(j.dump(), R"({"count":5,"is_success":true,"steps":4,"touches":[7,8]})");
  info.clear();
  EXPECT_EQ(info.size(), 4);
  EXPECT_EQ(info.to_json().dump(), R"({"count":0,"is_success":false,"steps":0,"touches":[]})");
  EXPECT_TRUE(info.list(hidden).empty());
}

}  // namespace
}  // namespace cradle::envs

// Score formulas on hand-made training logs.
#include "eval/scores.h"

#include <gtest/gtest.h>

namespace cradle::eval {
namespace {

using nlohmann::json;

json touch_entry(std::vector<int> right, std::vector<int> left, int steps = 1000) {
  return {{"right_hand_touches", right}, {"left_hand_touches", left}, {"steps", steps}};
}

TEST(Scores, SelfTouchIsUnionOverWindowOver68) {
  // The first (0-step) entry is outside the window while L <= 10,001.
  std::vector<json> log = {touch_entry({99, 98}, {97}, 0), touch_entry({3, 4, 5}, {6}),
                           touch_entry({4, 5, 7}, {6, 8})};
  EXPECT_DOUBLE_EQ(self_touch_score(log), (4.0 + 2.0) / 68);  // right {3,4,5,7}, left {6,8}
  EXPECT_DOUBLE_EQ(training_score(Behavior::kSelfTouch, log).value(), 6.0 / 68);
  EXPECT_DOUBLE_EQ(self_touch_score({}), 0);
  EXPECT_DOUBLE_EQ(self_touch_score({touch_entry({1}, {2}, 0)}), 0);
}

TEST(Scores, WindowIsTheLast10000Entries) {
  std::vector<json> log;
  log.push_back(touch_entry({100}, {}, 0));
  for (int i = 0; i < 10000; ++i) log.push_back(touch_entry({i % 30}, {}));
  // L = 10,001: the window is the last 10,000 entries, the first one is left out.
  EXPECT_EQ(scored_window(log).size(), 10000u);
  EXPECT_DOUBLE_EQ(self_touch_score(log), 30.0 / 68);
  // One more entry: the window slides, and the oldest scored entry (i = 0, geom 0) drops out of
  // the window but geom 0 is still present later; entry 0 (geom 100) stays outside.
  log.push_back(touch_entry({31}, {}));
  EXPECT_EQ(scored_window(log).size(), 10000u);
  EXPECT_EQ(scored_window(log).front(), &log[2]);
  EXPECT_DOUBLE_EQ(self_touch_score(log), 31.0 / 68);
}

TEST(Scores, HandRegardBothDefinitions) {
  const std::vector<json> log = {{{"steps", 0}, {"right_eye_right_hand", 1}},
                                 {{"steps", 100},
                                  {"right_eye_right_hand", 40},
                                  {"right_eye_left_hand", 0},
                                  {"left_eye_right_hand", 40},
                                  {"left_eye_left_hand", 0},
                                  {"right_eye_either_hand", 40},
                                  {"left_eye_either_hand", 40}},
                                 {{"steps", 100},
                                  {"right_eye_right_hand", 10},
                                  {"right_eye_left_hand", 10},
                                  {"left_eye_right_hand", 0},
                                  {"left_eye_left_hand", 0},
                                  {"right_eye_either_hand", 20},
                                  {"left_eye_either_hand", 0}}};
  const auto s = hand_regard_score(log).value();
  // Reference: (80 + 20) / (4 x 200); either-hand: (60 + 40) / (2 x 200).
  EXPECT_DOUBLE_EQ(s.reference, 100.0 / 800);
  EXPECT_DOUBLE_EQ(s.either, 100.0 / 400);
  // One hand always in view of both eyes: 0.5 by the reference, 1 by the site's definition.
  const json always = {{"steps", 10},
                       {"right_eye_right_hand", 10},
                       {"left_eye_right_hand", 10},
                       {"right_eye_either_hand", 10},
                       {"left_eye_either_hand", 10}};
  const auto one = hand_regard_episode_score(always).value();
  EXPECT_DOUBLE_EQ(one.reference, 0.5);
  EXPECT_DOUBLE_EQ(one.either, 1.0);
  // No steps in the window: no score (the reference divides by zero).
  EXPECT_FALSE(hand_regard_score({log[0]}).has_value());
  EXPECT_FALSE(training_score(Behavior::kNone, log).has_value());
}

}  // namespace
}  // namespace cradle::eval

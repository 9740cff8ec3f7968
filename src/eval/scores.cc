#include "eval/scores.h"

#include <algorithm>
#include <set>

namespace cradle::eval {

std::vector<const nlohmann::json*> scored_window(const std::vector<nlohmann::json>& entries) {
  std::vector<const nlohmann::json*> window;
  const size_t count = std::min<size_t>(kScoreWindow, entries.empty() ? 0 : entries.size() - 1);
  for (size_t i = entries.size() - count; i < entries.size(); ++i) window.push_back(&entries[i]);
  return window;
}

double self_touch_score(const std::vector<nlohmann::json>& entries) {
  std::set<int> right, left;
  for (const nlohmann::json* e : scored_window(entries)) {
    for (int g : e->value("right_hand_touches", std::vector<int>{})) right.insert(g);
    for (int g : e->value("left_hand_touches", std::vector<int>{})) left.insert(g);
  }
  return static_cast<double>(right.size() + left.size()) / kSelfTouchDenominator;
}

namespace {
// Both hand-regard definitions over a set of entries.
std::optional<HandRegardScore> hand_regard_over(const std::vector<const nlohmann::json*>& set) {
  double pairs = 0, either = 0, steps = 0;
  for (const nlohmann::json* e : set) {
    for (const char* key : {"right_eye_right_hand", "right_eye_left_hand", "left_eye_right_hand",
                            "left_eye_left_hand"}) {
      pairs += e->value(key, 0);
    }
    either += e->value("right_eye_either_hand", 0) + e->value("left_eye_either_hand", 0);
    steps += e->value("steps", 0);
  }
  if (steps == 0) return std::nullopt;
  return HandRegardScore{.reference = pairs / (4 * steps), .either = either / (2 * steps)};
}
}  // namespace

std::optional<HandRegardScore> hand_regard_score(const std::vector<nlohmann::json>& entries) {
  return hand_regard_over(scored_window(entries));
}

std::optional<HandRegardScore> hand_regard_episode_score(const nlohmann::json& entry) {
  return hand_regard_over({&entry});
}

std::optional<double> training_score(Behavior behavior,
                                     const std::vector<nlohmann::json>& entries) {
  switch (behavior) {
    case Behavior::kSelfTouch:
      return self_touch_score(entries);
    case Behavior::kHandRegard:
      if (auto s = hand_regard_score(entries)) return s->reference;
      return std::nullopt;
    case Behavior::kNone:
      break;
  }
  return std::nullopt;
}

}  // namespace cradle::eval

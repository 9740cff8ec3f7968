// Benchmark scores from training-log entries (the JSON objects of training.jsonl, or the
// reference's training.pkl dicts).
//
// Self-touch (reference): (|union of right-hand geoms| + |union of left-hand geoms|) / 68 over the
// scored window. Hand regard (reference): sum of the four eye-hand counts / (4 x sum of steps)
// over the window. Hand regard (competition site): fraction of steps with either hand in view of
// each eye, averaged over the two eyes. The scored window is the reference's: the last
// min(10,000, L - 1) of L entries (the first, 0-step entry is left out while L <= 10,001).
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

#include "core/config.h"

namespace cradle::eval {

inline constexpr int kScoreWindow = 10000;
inline constexpr int kSelfTouchDenominator = 68;

// The entries the reference scores: the last min(kScoreWindow, L - 1).
std::vector<const nlohmann::json*> scored_window(const std::vector<nlohmann::json>& entries);

double self_touch_score(const std::vector<nlohmann::json>& entries);

struct HandRegardScore {
  double reference = 0;  // mean over the four eye-hand pairs
  double either = 0;     // mean over the eyes of the fraction with either hand in view
};
// nullopt when the window holds no steps (the reference divides by zero there).
std::optional<HandRegardScore> hand_regard_score(const std::vector<nlohmann::json>& entries);

// Both definitions for one entry (one episode).
std::optional<HandRegardScore> hand_regard_episode_score(const nlohmann::json& entry);

// The behaviour's headline score (self-touch, hand regard reference); nullopt for "none" or when
// there is nothing to score.
std::optional<double> training_score(Behavior behavior, const std::vector<nlohmann::json>& entries);

}  // namespace cradle::eval

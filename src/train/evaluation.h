// `cradle evaluate`: scores the training log, then runs evaluation episodes with a policy and
// writes trajectories (npz), videos (mp4/avi), evaluation.json and PNG plots under save_dir.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/config.h"
#include "envs/babybench.h"
#include "eval/scores.h"

namespace cradle::train {

// Fills `action` for the env's current observation.
using Policy = std::function<void(const envs::BabyBenchEnv& env, std::span<double> action)>;

struct EvaluationOptions {
  int episodes = 10;
  int duration = 1000;     // env steps per episode
  bool render = true;      // write one video per episode
  std::uint64_t seed = 0;  // episode i resets with seed + i; the random policy draws from seed
  std::string video_extension = ".mp4";  // or ".avi"
  double video_fps = 0;                  // 0: real time (1 / env step duration)
  bool quiet = false;                    // no per-episode lines on stdout
  // How the policy acts, recorded in evaluation.json: "random" (no policy), "mean" (a checkpoint's
  // deterministic action), "sampled" (drawn from its distribution) or "custom" (a caller's
  // function).
  std::string policy_actions = "random";
};

struct EpisodeResult {
  int steps = 0;
  double score = 0;                                  // the behaviour's episode score (NaN for none)
  std::optional<eval::HandRegardScore> hand_regard;  // both definitions, hand regard only
  std::vector<int> right_hand_touches, left_hand_touches;
  double wall_seconds = 0;
};

struct EvaluationReport {
  std::optional<double> training_score;  // from logs/training.jsonl, if there is one
  std::optional<eval::HandRegardScore> training_hand_regard;
  int training_episodes = 0;
  std::vector<EpisodeResult> episodes;
  double mean = 0, std = 0;  // of the episode scores
  nlohmann::json to_json() const;
};

// Runs the evaluation. A null policy acts uniformly at random within the action bounds.
EvaluationReport evaluate(const Config& config, const EvaluationOptions& options,
                          const Policy& policy = nullptr);

// The random policy: uniform within the action bounds, from its own seeded generator.
Policy random_policy(std::uint64_t seed);

}  // namespace cradle::train

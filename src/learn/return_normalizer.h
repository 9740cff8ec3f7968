// VecNormalize's return normalisation (Baselines' ppo2 and SB3's norm_reward; PPO's
// normalize_returns): each env keeps its discounted return ret = gamma ret + r, zeroed when an
// episode ends; a running mean and variance of ret over every step are kept; the learner trains
// on r / sqrt(var + 1e-8) clipped to +-clip. The statistics are part of the learner's checkpoint,
// so a resumed run scales its rewards exactly as the uninterrupted one.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "learn/vec_env.h"

namespace cradle::learn {

// The running statistics of the discounted return (count starts at 1e-4, as VecNormalize's).
struct ReturnStatistics {
  double mean = 0, var = 1, count = 1e-4;
  friend bool operator==(const ReturnStatistics&, const ReturnStatistics&) = default;
};

class ReturnNormalizer {
 public:
  explicit ReturnNormalizer(double gamma, double clip = 10.0) : gamma_(gamma), clip_(clip) {}
  // Fresh episodes in every env (a learn() call's reset): the discounted returns restart at 0.
  void start();
  // The reward hook (learn/learner.h RewardHook): scales `rewards` in place. Autoreset steps
  // (no transition) neither extend ret nor enter the statistics.
  void operator()(const VecEnv& env, std::span<const double> actions, std::span<double> rewards);
  const ReturnStatistics& statistics() const { return stats_; }
  void set_statistics(const ReturnStatistics& stats) { stats_ = stats; }

 private:
  double gamma_, clip_;
  ReturnStatistics stats_;
  std::vector<double> ret_;          // per env
  std::vector<std::uint8_t> ended_;  // per env: its episode ended at the previous step
};

}  // namespace cradle::learn

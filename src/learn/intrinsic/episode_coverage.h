// episode_coverage: the self-touch score's own increments, as a reward.
//
//   r_t = |first touches in step t| / 68
//
// where a first touch is a geom id appended in step t to the info list "right_hand_touches" or
// "left_hand_touches", i.e. a geom that hand touches for the first time in the episode (the env's
// self-touch behaviour decides what a touch is). Summed over an episode, r is exactly that
// episode's self-touch score (|geoms touched by right| + |by left|) / 68, the quantity the
// final-policy evaluation averages over episodes. Unlike body_part_novelty, nothing fades over
// training: a geom found again in a new episode pays as much as the first time.
//
// State: how many entries of each list were seen, per env (reset at every episode start).
#pragma once

#include <array>
#include <cstddef>
#include <span>
#include <string_view>
#include <vector>

#include "learn/intrinsic/reward.h"

namespace cradle::learn::intrinsic {

class EpisodeCoverage final : public IntrinsicReward {
 public:
  // The self-touch score's denominator: MIMo's geoms a hand may touch (babybench_layer.md §4.2).
  static constexpr double kScoreGeoms = 68.0;

  explicit EpisodeCoverage(double scale = 1.0) : IntrinsicReward(scale) {}

  std::string_view name() const override { return "episode_coverage"; }
  // Throws UserError when the env publishes neither hand's touch list.
  void bind(const VecEnv& env) override;
  void reset(const VecEnv& env) override;
  void compute(const VecEnv& env, std::span<const double> actions,
               std::span<double> rewards) override;

 private:
  std::array<int, 2> slots_ = {-1, -1};           // info slots of the right and left hands' lists
  std::vector<std::array<std::size_t, 2>> seen_;  // list entries already paid, per env and hand
  detail::EpisodeStarts starts_;
};

}  // namespace cradle::learn::intrinsic

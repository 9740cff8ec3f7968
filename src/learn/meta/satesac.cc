// SaTESAC's sampler, one: one training env chosen at random; a batch from it sorted by average
// return; positives the top, negatives the bottom (same task, worse skill).
#include "learn/meta/samplers.h"

namespace cradle::learn::meta {

ContrastSample sample_one(const TrajectoryReplay& replay, int batch, double neg_ratio, Rng& rng) {
  const int negatives = negative_count(batch, neg_ratio);
  const int env = static_cast<int>(rng.next() % replay.envs());
  std::vector<long> drawn = replay.sample(env, batch, rng);
  sort_by_return(replay, drawn);
  ContrastSample out;
  out.positives.assign(drawn.begin(), drawn.end() - negatives);
  out.negatives.assign(drawn.end() - negatives, drawn.end());
  out.positive_return = mean_return(replay, out.positives);
  out.negative_return = mean_return(replay, out.negatives);
  return out;
}

}  // namespace cradle::learn::meta

// SaCCMAll's sampler, all: a batch drawn evenly over every training env, sorted by average return
// across envs; positives the top, negatives the bottom.
#include "learn/meta/samplers.h"

namespace cradle::learn::meta {

ContrastSample sample_all(const TrajectoryReplay& replay, int batch, double neg_ratio, Rng& rng) {
  const int negatives = negative_count(batch, neg_ratio);
  std::vector<long> drawn = sample_even(replay, batch, rng);
  sort_by_return(replay, drawn);
  ContrastSample out;
  out.positives.assign(drawn.begin(), drawn.end() - negatives);
  out.negatives.assign(drawn.end() - negatives, drawn.end());
  out.positive_return = mean_return(replay, out.positives);
  out.negative_return = mean_return(replay, out.negatives);
  return out;
}

}  // namespace cradle::learn::meta

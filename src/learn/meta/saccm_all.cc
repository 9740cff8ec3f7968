// SaCCMAll's sampler, all: a batch drawn evenly over every training env, sorted by average return
// across envs; positives the top, negatives the bottom.
#include "learn/meta/samplers.h"

namespace cradle::learn::meta {

ContrastSample sample_all(const TrajectoryReplay& replay, int batch, double neg_ratio, Rng& rng) {
  return split_by_return(replay, sample_even(replay, batch, rng), negative_count(batch, neg_ratio));
}

}  // namespace cradle::learn::meta

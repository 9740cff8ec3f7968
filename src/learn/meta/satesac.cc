// SaTESAC's sampler, one: one training env chosen at random; a batch from it sorted by average
// return; positives the top, negatives the bottom (same task, worse skill).
#include "learn/meta/samplers.h"

namespace cradle::learn::meta {

ContrastSample sample_one(const TrajectoryReplay& replay, int batch, double neg_ratio, Rng& rng) {
  const int env = static_cast<int>(rng.next() % replay.envs());
  return split_by_return(replay, replay.sample(env, batch, rng), negative_count(batch, neg_ratio));
}

}  // namespace cradle::learn::meta

// CCM's sampler, env_diff: positives from one training env i chosen at random, negatives from
// another env j != i; the loss weight uses the constant returns 1 and 0 (so w = lambda).
#include "learn/meta/samplers.h"

namespace cradle::learn::meta {

ContrastSample sample_env_diff(const TrajectoryReplay& replay, int batch, double neg_ratio,
                               Rng& rng) {
  const int negatives = negative_count(batch, neg_ratio);
  const int n = replay.envs();
  const int i = static_cast<int>(rng.next() % n);
  const int j = (i + 1 + static_cast<int>(rng.next() % (n - 1))) % n;  // uniform over j != i
  ContrastSample out;
  out.positives = replay.sample(i, batch - negatives, rng);
  out.negatives = replay.sample(j, negatives, rng);
  out.positive_return = 1.0;
  out.negative_return = 0.0;
  return out;
}

}  // namespace cradle::learn::meta

// SaCCM's sampler, half: the negatives are the lowest-return part of a batch drawn evenly over
// every training env; the positives come from one env (envs tried in random order) whose stored
// trajectories beat the best negative: drawn without replacement when there are enough, else
// with replacement. When no env has a trajectory above the best negative (all returns equal,
// early in training), the positives are the top of the even batch, as in SaCCMAll.
#include <algorithm>
#include <numeric>

#include "learn/meta/samplers.h"

namespace cradle::learn::meta {

ContrastSample sample_half(const TrajectoryReplay& replay, int batch, double neg_ratio, Rng& rng) {
  const int negatives = negative_count(batch, neg_ratio);
  const int positives = batch - negatives;
  std::vector<long> drawn = sample_even(replay, batch, rng);
  sort_by_return(replay, drawn);
  ContrastSample out;
  out.negatives.assign(drawn.end() - negatives, drawn.end());
  const double best_negative = replay.average_return(out.negatives.front());

  // Envs in random order (Fisher-Yates on the Rng).
  std::vector<int> order(replay.envs());
  std::iota(order.begin(), order.end(), 0);
  for (int k = static_cast<int>(order.size()) - 1; k > 0; --k) {
    std::swap(order[k], order[rng.next() % (k + 1)]);
  }
  for (int env : order) {
    std::vector<long> better;
    for (int k = 0; k < replay.stored(env); ++k) {
      const long index = replay.index(env, k);
      if (replay.average_return(index) > best_negative) better.push_back(index);
    }
    if (better.empty()) continue;
    if (static_cast<int>(better.size()) >= positives) {
      for (int k = 0; k < positives; ++k) {  // partial shuffle: without replacement
        std::swap(better[k], better[k + rng.next() % (better.size() - k)]);
      }
      out.positives.assign(better.begin(), better.begin() + positives);
    } else {
      for (int k = 0; k < positives; ++k)
        out.positives.push_back(better[rng.next() % better.size()]);
    }
    break;
  }
  if (out.positives.empty()) out.positives.assign(drawn.begin(), drawn.begin() + positives);
  out.positive_return = mean_return(replay, out.positives);
  out.negative_return = mean_return(replay, out.negatives);
  return out;
}

}  // namespace cradle::learn::meta

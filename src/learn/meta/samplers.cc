#include "learn/meta/samplers.h"

#include <algorithm>

namespace cradle::learn::meta {

int negative_count(int batch, double neg_ratio) {
  return std::clamp(static_cast<int>(batch * neg_ratio), 1, batch - 1);
}

std::vector<long> sample_even(const TrajectoryReplay& replay, int count, Rng& rng) {
  std::vector<long> out;
  out.reserve(count);
  for (int e = 0; e < replay.envs(); ++e) {
    const int n = count / replay.envs() + (e < count % replay.envs() ? 1 : 0);
    if (n == 0) continue;
    const std::vector<long> part = replay.sample(e, n, rng);
    out.insert(out.end(), part.begin(), part.end());
  }
  return out;
}

void sort_by_return(const TrajectoryReplay& replay, std::vector<long>& indices) {
  std::stable_sort(indices.begin(), indices.end(), [&](long a, long b) {
    return replay.average_return(a) > replay.average_return(b);
  });
}

double mean_return(const TrajectoryReplay& replay, const std::vector<long>& indices) {
  double sum = 0;
  for (long i : indices) sum += replay.average_return(i);
  return indices.empty() ? 0.0 : sum / static_cast<double>(indices.size());
}

ContrastSample split_by_return(const TrajectoryReplay& replay, std::vector<long> drawn,
                               int negatives) {
  sort_by_return(replay, drawn);
  ContrastSample out;
  out.positives.assign(drawn.begin(), drawn.end() - negatives);
  out.negatives.assign(drawn.end() - negatives, drawn.end());
  out.positive_return = mean_return(replay, out.positives);
  out.negative_return = mean_return(replay, out.negatives);
  return out;
}

ContrastSample sample_contrast(Contrast contrast, const TrajectoryReplay& replay, int batch,
                               double neg_ratio, Rng& rng) {
  switch (contrast) {
    case Contrast::kEnvDiff:
      return sample_env_diff(replay, batch, neg_ratio, rng);
    case Contrast::kOne:
      return sample_one(replay, batch, neg_ratio, rng);
    case Contrast::kHalf:
      return sample_half(replay, batch, neg_ratio, rng);
    case Contrast::kAll:
      return sample_all(replay, batch, neg_ratio, rng);
    case Contrast::kNone:
      break;
  }
  return {};
}

}  // namespace cradle::learn::meta

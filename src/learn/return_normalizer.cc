#include "learn/return_normalizer.h"

#include <algorithm>
#include <cmath>

namespace cradle::learn {

void ReturnNormalizer::start() {
  std::fill(ret_.begin(), ret_.end(), 0.0);
  std::fill(ended_.begin(), ended_.end(), 0);
}

void ReturnNormalizer::operator()(const VecEnv& env, std::span<const double>,
                                  std::span<double> rewards) {
  const int n = env.num_envs();
  if (static_cast<int>(ret_.size()) != n) {
    ret_.assign(n, 0.0);
    ended_.assign(n, 0);
  }
  for (int i = 0; i < n; ++i) {
    // This step only reset the env (next-step autoreset): no reward to scale.
    if (ended_[i]) {
      ended_[i] = 0;
      continue;
    }
    ret_[i] = gamma_ * ret_[i] + rewards[i];
    // Chan et al.'s merge of one sample into the running mean and variance.
    const double delta = ret_[i] - stats_.mean, total = stats_.count + 1;
    stats_.mean += delta / total;
    stats_.var = (stats_.var * stats_.count + delta * delta * stats_.count / total) / total;
    stats_.count = total;
    rewards[i] = std::clamp(rewards[i] / std::sqrt(stats_.var + 1e-8), -clip_, clip_);
    if (env.terminated()[i] || env.truncated()[i]) {
      ret_[i] = 0;
      ended_[i] = 1;
    }
  }
}

}  // namespace cradle::learn

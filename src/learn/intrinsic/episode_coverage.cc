#include "learn/intrinsic/episode_coverage.h"

#include "core/error.h"

namespace cradle::learn::intrinsic {

void EpisodeCoverage::bind(const VecEnv& env) {
  const int n = env.num_envs();
  const char* lists[2] = {"right_hand_touches", "left_hand_touches"};
  for (int h = 0; h < 2; ++h) slots_[h] = n > 0 ? env.info(0).find(lists[h]) : -1;
  if (n > 0 && slots_[0] < 0 && slots_[1] < 0) {
    throw UserError(
        "episode_coverage needs the self-touch info lists right_hand_touches/left_hand_touches "
        "(behavior: self_touch)");
  }
  seen_.assign(n, {0, 0});
  starts_.assign(n, true);
}

void EpisodeCoverage::reset(const VecEnv& env) {
  if (static_cast<int>(seen_.size()) != env.num_envs()) bind(env);
  seen_.assign(env.num_envs(), {0, 0});
  starts_.assign(env.num_envs(), false);
}

void EpisodeCoverage::compute(const VecEnv& env, std::span<const double>,
                              std::span<double> rewards) {
  if (seen_.empty()) bind(env);
  for (int i = 0; i < env.num_envs(); ++i) {
    const int id = env.env_id(i);
    // An autoreset step starts a new episode: its lists start empty again.
    if (starts_[id]) seen_[id] = {0, 0};
    const envs::Info& info = env.info(i);
    std::size_t found = 0;
    for (int h = 0; h < 2; ++h) {
      if (slots_[h] < 0) continue;
      const std::size_t size = info.list(slots_[h]).size();
      if (size < seen_[id][h]) seen_[id][h] = 0;  // the env reset its lists behind our back
      found += size - seen_[id][h];
      seen_[id][h] = size;
    }
    rewards[i] += scale() * static_cast<double>(found) / kScoreGeoms;
  }
  starts_.record_flags(env);
}

}  // namespace cradle::learn::intrinsic

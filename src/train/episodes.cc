#include "train/episodes.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <optional>
#include <vector>

#include "core/error.h"

namespace cradle::train {

namespace {

// Plays `count` episodes, episode e reset with seed_of(e) (none: the env's own stream).
std::vector<EpisodeOutcome> play(
    envs::Env& env, const EpisodePolicy& policy, std::size_t count,
    const std::function<std::optional<std::uint64_t>(std::size_t)>& seed_of, int max_steps,
    const EpisodeStepFn& on_step, const EpisodeStartFn& on_start, bool fixed_length) {
  std::vector<double> action(env.action_space().size());
  const int success = env.info().find("is_success");
  const int failure = env.info().find("is_failure");
  std::vector<EpisodeOutcome> out;
  for (size_t e = 0; e < count; ++e) {
    const std::optional<std::uint64_t> seed = seed_of(e);
    EpisodeOutcome r{.seed = seed.value_or(0)};
    if (on_start) on_start(static_cast<int>(e), env);
    env.reset(seed);
    if (policy.new_episode) policy.new_episode();
    while (true) {
      policy.act(env.observation(), action);
      const envs::StepResult s = env.step(action);
      r.episode_return += s.reward;
      ++r.length;
      if (on_step) on_step(static_cast<int>(e), env, s);
      const bool capped = max_steps > 0 && r.length >= max_steps;
      if (((s.terminated || s.truncated) && !fixed_length) || capped) {
        r.truncated = !s.terminated;
        break;
      }
    }
    r.success = success >= 0 && env.info().flag(success);
    r.failure = failure >= 0 && env.info().flag(failure);
    r.score = env.score();
    out.push_back(r);
  }
  return out;
}

}  // namespace

std::vector<EpisodeOutcome> run_episodes(envs::Env& env, const EpisodePolicy& policy,
                                         std::span<const std::uint64_t> seeds, int max_steps,
                                         const EpisodeStepFn& on_step,
                                         const EpisodeStartFn& on_start, bool fixed_length) {
  if (fixed_length && max_steps < 1) throw UserError("a fixed-length rollout needs max_steps >= 1");
  return play(
      env, policy, seeds.size(), [&](std::size_t e) { return std::optional(seeds[e]); }, max_steps,
      on_step, on_start, fixed_length);
}

std::vector<EpisodeOutcome> run_episodes(envs::Env& env, const EpisodePolicy& policy, int episodes,
                                         int max_steps, const EpisodeStepFn& on_step,
                                         const EpisodeStartFn& on_start) {
  return play(
      env, policy, static_cast<std::size_t>(std::max(episodes, 0)),
      [](std::size_t) { return std::optional<std::uint64_t>(); }, max_steps, on_step, on_start,
      /*fixed_length=*/false);
}

nlohmann::ordered_json episodes_json(const std::vector<EpisodeOutcome>& episodes) {
  nlohmann::ordered_json j;
  double sum = 0, sum2 = 0, length = 0, successes = 0;
  j["episodes"] = nlohmann::ordered_json::array();
  for (const EpisodeOutcome& r : episodes) {
    nlohmann::ordered_json e;
    e["seed"] = r.seed;
    e["return"] = r.episode_return;
    e["length"] = r.length;
    e["success"] = r.success;
    e["failure"] = r.failure;
    e["truncated"] = r.truncated;
    if (std::isfinite(r.score)) e["score"] = r.score;
    j["episodes"].push_back(e);
    sum += r.episode_return;
    sum2 += r.episode_return * r.episode_return;
    length += r.length;
    successes += r.success ? 1 : 0;
  }
  const double n = static_cast<double>(episodes.size());
  if (n > 0) {
    const double mean = sum / n;
    j["mean_return"] = mean;
    j["std_return"] = std::sqrt(std::max(0.0, sum2 / n - mean * mean));
    j["mean_length"] = length / n;
    j["success_rate"] = successes / n;
  }
  return j;
}

}  // namespace cradle::train

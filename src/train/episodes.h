// One evaluation rollout for every env family: whole episodes of a policy on an env, each from
// its own seed, with what the run records of each (return, length, the task's success and
// failure flags and score). Runs by env id evaluate their trained policy with it.
#pragma once

#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <span>
#include <vector>

#include "envs/env.h"

namespace cradle::train {

struct EpisodeOutcome {
  std::uint64_t seed = 0;
  double episode_return = 0;
  int length = 0;
  bool success = false;  // info "is_success" at the episode's last step (false without one)
  bool failure = false;  // info "is_failure" likewise
  double score = 0;      // the env's score() at the end (NaN when the task has none)
  bool truncated = false;
};

// The policy: writes the action for an observation. `new_episode` is called before each
// episode's first action (a policy with memory restarts it).
struct EpisodePolicy {
  std::function<void(const envs::ObservationBuffers&, std::span<double>)> act;
  std::function<void()> new_episode;
};

// Called after every step (e.g. to film or trace), with the episode's index.
using EpisodeStepFn = std::function<void(int episode, const envs::Env&, const envs::StepResult&)>;

// Called before each episode's reset (e.g. to set the episode's task as reset options).
using EpisodeStartFn = std::function<void(int episode, envs::Env&)>;

// Plays one episode per seed on `env` (reset with that seed) until it terminates or truncates,
// or after max_steps steps when max_steps > 0 (then counted as truncated). With `fixed_length`,
// every episode is exactly max_steps steps, whatever the env says (BabyBench's evaluation of a
// duration, which runs on past the env's own episode length).
std::vector<EpisodeOutcome> run_episodes(envs::Env& env, const EpisodePolicy& policy,
                                         std::span<const std::uint64_t> seeds, int max_steps = 0,
                                         const EpisodeStepFn& on_step = nullptr,
                                         const EpisodeStartFn& on_start = nullptr,
                                         bool fixed_length = false);
// The same for `episodes` episodes that go on with the env's own random stream (each reset
// without a seed, the outcomes' seed 0): SaMI's evaluation, whose env draws every episode's task
// from the stream of its one seed.
std::vector<EpisodeOutcome> run_episodes(envs::Env& env, const EpisodePolicy& policy, int episodes,
                                         int max_steps = 0, const EpisodeStepFn& on_step = nullptr,
                                         const EpisodeStartFn& on_start = nullptr);

// The results as evaluation.json writes them: per episode, then mean and std of the return,
// the mean length and the success rate.
nlohmann::ordered_json episodes_json(const std::vector<EpisodeOutcome>& episodes);

}  // namespace cradle::train

// Off-policy experience: the replay buffer and the collector that fills it from a VecEnv.
//
// The buffer keeps raw observations (before normalisation; images as uint8) and normalises
// them when sampled, with the statistics of that time, as SB3 does with VecNormalize: old
// transitions then read on the same scale as new ones. Actions are stored in [-1, 1] (the
// networks' scale); the env gets them rescaled to its Box bounds.
//
// Next-step autoreset and the buffer. The VecEnv reports an episode's final observation on the
// step that ends it and resets that env on the following call (reward 0, action ignored). So:
// - the next observation stored for a done step is the final observation: exactly what a
//   truncated episode bootstraps from (Q of the final observation); a terminated one stores
//   terminated = 1 and bootstraps nothing. Truncation is not stored (SB3's
//   handle_timeout_termination): the targets use (1 - terminated) only;
// - the autoreset step itself is no transition and is not stored.
// Nothing is approximated: every stored transition is (s, a, r, s') of one episode.
//
// Memory. Storage is preallocated but left uncommitted (torch::empty), so pages are used as
// the buffer fills. A buffer whose full size would need more than half of the machine's
// physical memory is refused (UserError naming buffer_size and the bytes it needs): the envs
// (about 300 MB each for BabyBench) and the networks need the rest.
#pragma once

#include <torch/torch.h>

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "learn/learner.h"
#include "learn/preprocess.h"
#include "learn/rollout.h"
#include "learn/vec_env.h"

namespace cradle::learn {

// Bytes a buffer of `capacity` transitions needs: observation and next observation (vector
// float32, images uint8), action float32, reward float32, terminated uint8.
double replay_bytes(long capacity, const ObsShape& shape, int action_size);
// Half of the physical memory (sysconf), the most a replay buffer may take.
double replay_memory_limit();
// Throws UserError unless 1 <= capacity and replay_bytes(capacity) <= limit_bytes.
void check_replay_memory(std::string_view algorithm, long capacity, const ObsShape& shape,
                         int action_size, double limit_bytes = replay_memory_limit());

class ReplayBuffer {
 public:
  ReplayBuffer(long capacity, const ObsShape& shape, int action_size);
  long capacity() const { return capacity_; }
  long size() const { return size_; }  // transitions held (at most capacity; oldest overwritten)

  // Stores row i of the batches as one transition for every i with keep[i] != 0. observation
  // and next: raw vectors (float32) and images; actions: [rows, action_size] float32 in [-1, 1].
  void add(const ObsBatch& observation, const torch::Tensor& actions,
           std::span<const double> rewards, const ObsBatch& next,
           std::span<const std::uint8_t> terminated, std::span<const std::uint8_t> keep);

  // Appends every transition of `staging` (oldest first), then empties it: the learner merging
  // what a collector thread stored (OffPolicyConfig::overlap_collection).
  void append(ReplayBuffer& staging);

  struct Sample {
    ObsBatch observations, next_observations;  // raw, as stored
    torch::Tensor actions;                     // [B, action_size] float32
    torch::Tensor rewards;                     // [B] float32
    torch::Tensor terminated;                  // [B] float32, 0 or 1
  };
  // `rows` transitions drawn uniformly with replacement (SB3's sampling). Requires size() > 0.
  Sample sample(int rows, at::Generator& generator) const;
  // Transitions at the given indices (int64), for tests.
  Sample gather(const torch::Tensor& index) const;

 private:
  // Stores row `from` of the sources as the next transition.
  void put(const ObsBatch& observation, const torch::Tensor& actions, const ObsBatch& next,
           long from, float reward, std::uint8_t terminated);

  long capacity_, size_ = 0, next_ = 0;
  ObsBatch observations_, next_observations_;
  torch::Tensor actions_, rewards_, terminated_;
  std::vector<long> image_bytes_;
};

// Steps a VecEnv with actions in [-1, 1] and stores its transitions in a replay buffer.
class TransitionCollector {
 public:
  TransitionCollector(VecEnv& env, ObservationPipeline& pipeline, RewardHook reward_hook);
  // Starts fresh episodes: resets every env with `seed` and reads the first observations.
  void start(std::uint64_t seed);
  // The current observations, normalised with the current statistics (one row per env).
  const ObsBatch& observation() const { return normalized_; }
  // Sends actions ([envs, action_size] in [-1, 1]) rescaled to the Box bounds, applies the
  // reward hook, stores every real transition (not autoreset steps) and reads the next
  // observations (updating the normaliser's statistics).
  void step(const torch::Tensor& actions, ReplayBuffer& buffer);
  EpisodeStats& episodes() { return stepper_.episodes(); }

 private:
  void normalize_current();

  VecEnv& env_;
  ObservationPipeline& pipeline_;
  EnvStepper stepper_;
  ObsBatch raw_, next_raw_, normalized_;
  std::vector<double> actions_;
};

// Rescales actions in [-1, 1] to the bounds: low + (a + 1) (high - low) / 2, clipped to them.
void unscale_actions(const torch::Tensor& actions, const Box& bounds, std::span<double> out);
// Throws UserError unless every bound of the action space is finite (off-policy learners
// squash their actions into the Box).
void check_bounded_actions(std::string_view algorithm, const Box& bounds);

}  // namespace cradle::learn

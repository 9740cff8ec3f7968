// SaMI's replay (tma_sami.md §6): per training task set, a ring of whole trajectories, each in a
// slot of max_len + 1 steps (observations o_0..o_len, actions a_0..a_{len-1}, rewards), so that a
// batch of trajectories is one [B, max_len + 1, .] gather, ready for one LSTM call. A slot being
// written is out of the sample pool until its trajectory ends.
//
// Average return of a trajectory: the sum of its rewards / its length. (SaMI divides by length + 1
// and adds one stale slot past the end; we drop the stale slot and divide by the length.)
#pragma once

#include <torch/torch.h>

#include <functional>
#include <span>
#include <string>
#include <vector>

#include "core/rng.h"

namespace cradle::learn::meta {

class TrajectoryReplay {
 public:
  // Throws UserError for a non-positive size.
  TrajectoryReplay(int envs, int capacity, int max_len, int obs_size, int action_size);

  int envs() const { return envs_; }
  int capacity() const { return capacity_; }
  int max_len() const { return max_len_; }
  int obs_size() const { return obs_size_; }
  int action_size() const { return action_size_; }

  // Starts env's next trajectory at its first observation, in the ring's next slot.
  void begin(int env, std::span<const float> observation);
  // Appends a step: the action taken, its reward and the next observation. A trajectory longer
  // than max_len is a logic error (std::logic_error).
  void add(int env, std::span<const float> action, double reward,
           std::span<const float> next_observation);
  // Ends env's trajectory: terminated (no bootstrap from its last observation) or truncated.
  void finish(int env, bool terminated);
  // Steps of env's trajectory in progress.
  int open_length(int env) const { return open_[env] ? length_[slot(env, head_[env])] : 0; }

  // Complete trajectories of env, and the global index of env's k-th (0 <= k < stored(env)).
  int stored(int env) const;
  long index(int env, int k) const;
  int env_of(long index) const { return static_cast<int>(index / capacity_); }
  double average_return(long index) const { return average_return_[index]; }
  int length(long index) const { return length_[index]; }
  // `count` indices of env's complete trajectories, uniformly with replacement.
  std::vector<long> sample(int env, int count, Rng& rng) const;

  struct Batch {
    torch::Tensor observations;   // [B, T, obs] float32, T = max_len + 1 (o_t; stale past len)
    torch::Tensor actions;        // [B, T, action] (a_t for t < len; zero after)
    torch::Tensor prev_actions;   // [B, T, action] (a_{t-1}; zero at t = 0)
    torch::Tensor rewards;        // [B, T] (r_t for t < len; zero after)
    torch::Tensor valid;          // [B, T] float: 1 for t < len (steps with a transition)
    torch::Tensor terminated;     // [B, T] float: 1 at the last step of a terminated trajectory
    torch::Tensor lengths;        // [B] int64
    std::vector<double> returns;  // average returns
    // The encoder's input [T, B, action + obs]: [a_{t-1}, o_t].
    torch::Tensor encoder_input() const;
  };
  Batch gather(const std::vector<long>& indices) const;

  // Checkpoints (learn/meta/sami_learner.h): every trajectory, open ones included, and the
  // ring's counters in a nested archive under `key`. stage() checks every size against this
  // replay's (UserError naming the first mismatch; nothing changes) and returns the copy, to run
  // once every other part of the checkpoint has passed its checks.
  void write(torch::serialize::OutputArchive& archive, const std::string& key) const;
  std::function<void()> stage(torch::serialize::InputArchive& archive, const std::string& key);

 private:
  long slot(int env, int k) const { return static_cast<long>(env) * capacity_ + k; }
  int envs_, capacity_, max_len_, obs_size_, action_size_;
  std::vector<float> observations_, actions_, rewards_;
  std::vector<int> length_;
  std::vector<std::uint8_t> terminated_;
  std::vector<double> average_return_;
  std::vector<int> head_, filled_;  // per env: the slot written next (or now), slots ever used
  std::vector<std::uint8_t> open_;  // per env: a trajectory is being written in head_
};

}  // namespace cradle::learn::meta

// What a learner needs from a data-parallel run, as a small interface so that learn/ does not
// depend on how ranks talk (dist/ implements it over torch's c10d; train/dist_sync.h adapts it).
// A learner given none (LearnerOptions::sync null) runs alone, unchanged. No LibTorch here: the
// tensor helpers are in learn/grad_tensors.h, so that the run and the CLI need not parse torch.h.
//
// The data-parallel contract every learner keeps: rank 0's initial parameters are broadcast, every
// gradient is averaged over the ranks before clipping and the optimiser step, and every decision
// that changes the number of collectives (minibatch counts, early stops, when training starts)
// is agreed on, so that every rank holds bitwise-identical parameters.
#pragma once

#include <span>
#include <string>
#include <utility>
#include <vector>

namespace cradle::learn {

class GradSync {
 public:
  virtual ~GradSync() = default;
  virtual int rank() const = 0;
  virtual int world_size() const = 0;
  // Element-wise sum (max: maximum) over the ranks, in place.
  virtual void all_reduce_sum(std::span<float> values) = 0;
  virtual void all_reduce_sum(std::span<double> values) = 0;
  virtual void all_reduce_max(std::span<double> values) = 0;
  // Rank 0's values to every rank.
  virtual void broadcast(std::span<float> values) = 0;
};

// True when there is more than one rank.
inline bool distributed(const GradSync* sync) { return sync != nullptr && sync->world_size() > 1; }
inline int world_size(const GradSync* sync) { return sync != nullptr ? sync->world_size() : 1; }

// The maximum of a value over the ranks (e.g. a count that decides how many collectives follow).
double agree_max(GradSync* sync, double value);
// The mean of a value over the ranks (e.g. PPO's approximate KL for its early stop).
double agree_mean(GradSync* sync, double value);
// The name of the first value that is not the same on every rank ("" when all agree), e.g. a
// setting every rank must share for the collectives to pair up.
std::string first_disagreement(GradSync& sync,
                               const std::vector<std::pair<std::string, double>>& values);

}  // namespace cradle::learn

// The methods of SaMI's table (tma_sami.md §6) and their contrastive samplers. Each method's
// distinctive part is how it picks positive and negative trajectories for the SaNCE/InfoNCE loss;
// each sampler lives in the file of its method (TESAC has none, so no file: method_contrast is
// kNone and ContextSac::update skips the SaNCE step):
//   TESAC                     none: the encoder learns through the critic's gradient only
//   CCM       (ccm.cc)        env_diff: positives from one training env, negatives from another
//   SaTESAC   (satesac.cc)    one: one env's batch sorted by average return, top / bottom
//   SaCCM     (saccm.cc)      half: negatives the low-return half of a batch over all envs,
//                             positives from one env whose returns beat the best negative
//   SaCCMAll  (saccm_all.cc)  all: a batch over all envs sorted, top / bottom
// With contrastive batch B, the negatives number clip(int(B neg_ratio), 1, B - 1) and the
// positives the rest.
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/rng.h"
#include "learn/meta/methods.h"
#include "learn/meta/trajectory_replay.h"

namespace cradle::learn::meta {

struct ContrastSample {
  std::vector<long> positives, negatives;  // replay indices
  // Mean average return of the positives and of the negatives (env_diff: the constants 1 and 0).
  double positive_return = 0, negative_return = 0;
};

int negative_count(int batch, double neg_ratio);

// Each needs at least one complete trajectory in every env (env_diff: and two envs); the caller
// checks replay.stored(env) > 0 first.
ContrastSample sample_env_diff(const TrajectoryReplay& replay, int batch, double neg_ratio,
                               Rng& rng);
ContrastSample sample_one(const TrajectoryReplay& replay, int batch, double neg_ratio, Rng& rng);
ContrastSample sample_half(const TrajectoryReplay& replay, int batch, double neg_ratio, Rng& rng);
ContrastSample sample_all(const TrajectoryReplay& replay, int batch, double neg_ratio, Rng& rng);
ContrastSample sample_contrast(Contrast contrast, const TrajectoryReplay& replay, int batch,
                               double neg_ratio, Rng& rng);

// Shared by the samplers: `count` indices drawn evenly over every env (the remainder to the first
// envs), and indices sorted by average return, highest first.
std::vector<long> sample_even(const TrajectoryReplay& replay, int count, Rng& rng);
void sort_by_return(const TrajectoryReplay& replay, std::vector<long>& indices);
double mean_return(const TrajectoryReplay& replay, const std::vector<long>& indices);
// SaTESAC's and SaCCMAll's split: `drawn` sorted by return, the last `negatives` the negatives
// and the rest the positives, with their mean returns.
ContrastSample split_by_return(const TrajectoryReplay& replay, std::vector<long> drawn,
                               int negatives);

}  // namespace cradle::learn::meta

// The SaNCE / InfoNCE loss of SaMI (tma_sami.md §6), binary-NCE form. Queries q are the online
// encoder's contexts of the positive trajectories, keys k+ and k- the target encoder's contexts
// of the positives and negatives. Every time step of every trajectory is one embedding; the
// steps from the terminal step on are zeroed (mask 0) and then give a logit of 0. With
// L2-normalised vectors and temperature tau,
//   L = - mean_{i,j} log sigmoid(q_i . k+_j / tau) - mean_{i,m} log(1 - sigmoid(q_i . k-_m / tau)),
// the means over all query x key pairs. The weight w = clip(lambda (R+ - R-), 0, 1) scales it.
#pragma once

#include <torch/torch.h>

namespace cradle::learn::meta {

// queries, positive_keys: [T, P, D]; negative_keys: [T, N, D]; masks [T, P] and [T, N] (1 keeps a
// step). `bilinear` (optional, [D, D]) replaces each key k by W k (the weighted InfoNCE).
torch::Tensor sance_loss(const torch::Tensor& queries, const torch::Tensor& positive_keys,
                         const torch::Tensor& negative_keys, const torch::Tensor& positive_mask,
                         const torch::Tensor& negative_mask, double temperature,
                         const torch::Tensor& bilinear = {});

// clip(lambda (positive_return - negative_return), 0, 1).
double sance_weight(double lambda, double positive_return, double negative_return);

}  // namespace cradle::learn::meta

// LibTorch helpers for the network teachers (GoalGAN, Setter-Solver): every random number comes
// from the teacher's own Rng, so a seed gives the same curriculum whatever torch's global state.
#pragma once

#include <torch/torch.h>

#include <vector>

#include "core/rng.h"

namespace cradle::teach {

// rows x cols standard normals.
torch::Tensor normal_tensor(Rng& rng, std::int64_t rows, std::int64_t cols);
// rows x cols uniforms in [lo, hi).
torch::Tensor uniform_tensor(Rng& rng, std::int64_t rows, std::int64_t cols, double lo, double hi);
// Xavier-uniform weights and zero biases for every Linear layer of `module`.
void xavier_init(torch::nn::Module& module, Rng& rng);
// A float32 row-major matrix from rows of floats (all the same size).
torch::Tensor rows_tensor(const std::vector<std::vector<float>>& rows);

}  // namespace cradle::teach

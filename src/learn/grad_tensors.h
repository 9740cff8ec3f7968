// The data-parallel contract of learn/grad_sync.h on LibTorch's tensors and modules: what the
// learners' own files call to average gradients, share rank 0's parameters and compare ranks.
#pragma once

#include <torch/torch.h>

#include <cstdint>
#include <vector>

#include "learn/grad_sync.h"

namespace cradle::learn {

// Averages a float32 contiguous tensor (a packed gradient) over the ranks, in place.
void average_gradients(GradSync* sync, const torch::Tensor& gradient);
// Every float32 parameter and buffer of `module` set to rank 0's.
void broadcast_module(GradSync* sync, torch::nn::Module& module);
void broadcast_tensor(GradSync* sync, const torch::Tensor& tensor);
// A rank's own random stream after every rank restored the same generator (resume): rank r > 0
// draws a new seed from it mixed with r, rank 0 keeps it, so the ranks explore differently.
void offset_generator(GradSync* sync, at::Generator& generator);
// FNV-1a over the bytes of tensors (parameters), to compare ranks and runs.
std::uint64_t tensor_hash(const std::vector<torch::Tensor>& tensors);

}  // namespace cradle::learn

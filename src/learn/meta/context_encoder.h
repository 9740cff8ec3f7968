// The SaMI context encoder (tma_sami.md §6): a one-layer LSTM of 128 units without biases, ReLU,
// then Linear(128 -> 6), read over the agent's own history [previous action, observation]. It runs
// over whole padded trajectories at training time ([T, B, input] in one LSTM call, from a zero
// state; padding after a trajectory's end cannot reach its earlier steps) and step by step with
// its (h, c) state carried when acting. The encoder pair holds the online copy, its momentum
// (target) copy updated by Polyak averaging, the bias-free 6 x 6 matrix W of the weighted InfoNCE,
// and the encoder's Adam.
#pragma once

#include <torch/torch.h>

#include <utility>

namespace cradle::learn::meta {

class ContextEncoderImpl : public torch::nn::Module {
 public:
  ContextEncoderImpl(int input, int hidden, int context, at::Generator& generator);
  int hidden() const { return hidden_; }
  // Contexts of every step of [T, B, input] sequences from a zero state: [T, B, context].
  torch::Tensor forward(const torch::Tensor& sequences);
  // One step of N streams: input [N, input], state {h, c} each [1, N, hidden] (updated in place
  // of the pair); returns the contexts [N, context].
  torch::Tensor step(const torch::Tensor& input, std::pair<torch::Tensor, torch::Tensor>& state);

 private:
  int hidden_ = 0;
  torch::nn::LSTM lstm_{nullptr};
  torch::nn::Linear head_{nullptr};
};
TORCH_MODULE(ContextEncoder);

struct EncoderPair {
  EncoderPair(int input, int hidden, int context, double learning_rate, at::Generator& generator);
  ContextEncoder online, target;
  torch::nn::Linear bilinear{nullptr};  // W of the weighted InfoNCE (bias-free)
  torch::optim::Adam optimizer;         // online encoder and W
  // target <- tau * online + (1 - tau) * target.
  void update_target(double tau);
};

}  // namespace cradle::learn::meta

#include "learn/meta/context_encoder.h"

#include <cmath>
#include <vector>

namespace cradle::learn::meta {
namespace {

// PyTorch's LSTM and Linear(hidden -> context) initialisation, uniform in +-1/sqrt(hidden) for
// both, from the caller's generator.
void init_uniform(torch::nn::Module& module, int hidden, at::Generator& generator) {
  torch::NoGradGuard no_grad;
  const double bound = 1.0 / std::sqrt(static_cast<double>(hidden));
  for (torch::Tensor& p : module.parameters()) {
    p.copy_(torch::rand(p.sizes(), generator, torch::kFloat32) * (2 * bound) - bound);
  }
}

std::vector<torch::Tensor> encoder_parameters(ContextEncoder& online, torch::nn::Linear& w) {
  std::vector<torch::Tensor> all = online->parameters();
  for (const torch::Tensor& p : w->parameters()) all.push_back(p);
  return all;
}

}  // namespace

ContextEncoderImpl::ContextEncoderImpl(int input, int hidden, int context, at::Generator& generator)
    : hidden_(hidden) {
  lstm_ =
      register_module("lstm", torch::nn::LSTM(torch::nn::LSTMOptions(input, hidden).bias(false)));
  head_ = register_module("head", torch::nn::Linear(hidden, context));
  init_uniform(*this, hidden, generator);
}

torch::Tensor ContextEncoderImpl::forward(const torch::Tensor& sequences) {
  const torch::Tensor h = std::get<0>(lstm_->forward(sequences));
  return head_->forward(torch::relu(h));
}

torch::Tensor ContextEncoderImpl::step(const torch::Tensor& input,
                                       std::pair<torch::Tensor, torch::Tensor>& state) {
  auto [out, next] = lstm_->forward(input.unsqueeze(0), std::make_tuple(state.first, state.second));
  state = {std::get<0>(next), std::get<1>(next)};
  return head_->forward(torch::relu(out.squeeze(0)));
}

EncoderPair::EncoderPair(int input, int hidden, int context, double learning_rate,
                         at::Generator& generator)
    : online(input, hidden, context, generator),
      target(input, hidden, context, generator),
      bilinear(torch::nn::LinearOptions(context, context).bias(false)),
      optimizer(encoder_parameters(online, bilinear), torch::optim::AdamOptions(learning_rate)) {
  {
    torch::NoGradGuard no_grad;
    const double bound = 1.0 / std::sqrt(static_cast<double>(context));
    bilinear->weight.copy_(torch::rand(bilinear->weight.sizes(), generator) * (2 * bound) - bound);
  }
  update_target(1.0);  // the target starts as a copy
  for (torch::Tensor& p : target->parameters()) p.requires_grad_(false);
}

void EncoderPair::update_target(double tau) {
  torch::NoGradGuard no_grad;
  const std::vector<torch::Tensor> from = online->parameters();
  std::vector<torch::Tensor> to = target->parameters();
  for (size_t i = 0; i < to.size(); ++i) to[i].mul_(1.0 - tau).add_(from[i], tau);
}

}  // namespace cradle::learn::meta

#include "learn/intrinsic/icm.h"

#include "learn/checkpoint.h"

namespace cradle::learn::intrinsic {

void Icm::build(int features, int actions, at::Generator& gen) {
  forward_ = make_mlp(features + actions, options().hidden, features, gen);
  optimizer_ = std::make_unique<torch::optim::Adam>(
      forward_->parameters(), torch::optim::AdamOptions(options().learning_rate));
}

torch::Tensor Icm::predict(const torch::Tensor& s, const torch::Tensor& a) {
  return s + forward_->forward(torch::cat({s, a}, 1));
}

torch::Tensor Icm::score(const torch::Tensor& s, const torch::Tensor& a,
                         const torch::Tensor& next) {
  return (predict(s, a) - next).pow(2).mean(1);
}

double Icm::train_step(const std::function<Batch()>& draw) {
  const Batch b = draw();
  torch::Tensor loss = torch::mse_loss(predict(b.s, b.a), b.next);
  optimizer_->zero_grad();
  loss.backward();
  optimizer_->step();
  return loss.item<double>();
}

void Icm::save_models(torch::serialize::OutputArchive& archive) const {
  torch::serialize::OutputArchive model;
  forward_->save(model);
  archive.write("forward", model);
  // In parameter order: LibTorch's own optimiser format keys its state by tensor address, so
  // its order (and the checkpoint's bytes) changed from run to run.
  write_optimizer(archive, "optimizer", *optimizer_);
}

void Icm::load_models(torch::serialize::InputArchive& archive) {
  torch::serialize::InputArchive model;
  archive.read("forward", model);
  forward_->load(model);
  read_optimizer(archive, "optimizer", *optimizer_);
}

}  // namespace cradle::learn::intrinsic

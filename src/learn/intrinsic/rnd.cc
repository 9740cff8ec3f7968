#include "learn/intrinsic/rnd.h"

#include "learn/checkpoint.h"

namespace cradle::learn::intrinsic {

void Rnd::build(int features, int, at::Generator& gen) {
  target_ = make_mlp(features, options().hidden, out_, gen);
  for (auto& p : target_->parameters()) p.set_requires_grad(false);
  predictor_ = make_mlp(features, options().hidden, out_, gen);
  optimizer_ = std::make_unique<torch::optim::Adam>(
      predictor_->parameters(), torch::optim::AdamOptions(options().learning_rate));
}

torch::Tensor Rnd::score(const torch::Tensor&, const torch::Tensor&, const torch::Tensor& next) {
  return (predictor_->forward(next) - target_->forward(next)).pow(2).mean(1);
}

double Rnd::train_step(const std::function<Batch()>& draw) {
  const Batch b = draw();
  torch::Tensor target;
  {
    torch::NoGradGuard no_grad;
    target = target_->forward(b.next);
  }
  torch::Tensor loss = torch::mse_loss(predictor_->forward(b.next), target);
  optimizer_->zero_grad();
  loss.backward();
  optimizer_->step();
  return loss.item<double>();
}

void Rnd::save_models(torch::serialize::OutputArchive& archive) const {
  torch::serialize::OutputArchive target, predictor;
  target_->save(target);
  predictor_->save(predictor);
  archive.write("target", target);
  archive.write("predictor", predictor);
  // In parameter order: LibTorch's own optimiser format keys its state by tensor address, so
  // its order (and the checkpoint's bytes) changed from run to run.
  write_optimizer(archive, "optimizer", *optimizer_);
}

void Rnd::load_models(torch::serialize::InputArchive& archive) {
  torch::serialize::InputArchive target, predictor;
  archive.read("target", target);
  archive.read("predictor", predictor);
  target_->load(target);
  predictor_->load(predictor);
  read_optimizer(archive, "optimizer", *optimizer_);
}

}  // namespace cradle::learn::intrinsic

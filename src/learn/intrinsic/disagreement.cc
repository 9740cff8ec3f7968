#include "learn/intrinsic/disagreement.h"

#include <string>

#include "core/error.h"
#include "learn/checkpoint.h"

namespace cradle::learn::intrinsic {

Disagreement::Disagreement(double scale, Options options)
    : LearnedReward(scale, options.learned), count_(options.models) {
  if (count_ < 2) throw UserError("disagreement: the ensemble needs at least 2 models");
}

void Disagreement::build(int features, int actions, at::Generator& gen) {
  models_.clear();
  std::vector<torch::Tensor> parameters;
  for (int k = 0; k < count_; ++k) {
    models_.push_back(make_mlp(features + actions, options().hidden, features, gen));
    for (const torch::Tensor& p : models_.back()->parameters()) parameters.push_back(p);
  }
  optimizer_ = std::make_unique<torch::optim::Adam>(
      parameters, torch::optim::AdamOptions(options().learning_rate));
}

torch::Tensor Disagreement::score(const torch::Tensor& s, const torch::Tensor& a,
                                  const torch::Tensor&) {
  const torch::Tensor input = torch::cat({s, a}, 1);
  std::vector<torch::Tensor> predictions;
  for (auto& model : models_) predictions.push_back(model->forward(input));
  // The common s cancels in the variance: Var_k(s + g_k) = Var_k(g_k). (Written out: LibTorch
  // 1.13's var() over the leading dimension is some 15 times slower on these shapes.)
  const torch::Tensor stacked = torch::stack(predictions);
  return (stacked - stacked.mean(0)).pow(2).mean(0).mean(1);
}

double Disagreement::train_step(const std::function<Batch()>& draw) {
  // Member k trains on minibatch k; one optimiser step on the mean of the members' losses
  // (Adam's per-parameter scaling makes the 1 / K factor immaterial).
  torch::Tensor loss = torch::zeros({});
  for (auto& model : models_) {
    const Batch b = draw();
    loss = loss + torch::mse_loss(b.s + model->forward(torch::cat({b.s, b.a}, 1)), b.next);
  }
  loss = loss / count_;
  optimizer_->zero_grad();
  loss.backward();
  optimizer_->step();
  return loss.item<double>();
}

void Disagreement::save_models(torch::serialize::OutputArchive& archive) const {
  for (int k = 0; k < count_; ++k) {
    torch::serialize::OutputArchive model;
    models_[k]->save(model);
    archive.write("model" + std::to_string(k), model);
  }
  // In parameter order: LibTorch's own optimiser format keys its state by tensor address, so
  // its order (and the checkpoint's bytes) changed from run to run.
  write_optimizer(archive, "optimizer", *optimizer_);
}

void Disagreement::load_models(torch::serialize::InputArchive& archive) {
  for (int k = 0; k < count_; ++k) {
    torch::serialize::InputArchive model;
    archive.read("model" + std::to_string(k), model);
    models_[k]->load(model);
  }
  read_optimizer(archive, "optimizer", *optimizer_);
}

}  // namespace cradle::learn::intrinsic

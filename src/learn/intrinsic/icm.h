// icm: forward-model curiosity (after Pathak et al. 2017's intrinsic curiosity module).
//
//   raw_t = || s_t + g([s_t, a_t]) - s_{t+1} ||^2 / D
//
// s is the normalised D-value feature vector of features.h (proprioception, pooled touch, pooled
// grey images), which stands in for ICM's learned encoder phi: it is already compact and, unlike a
// pixel encoder, holds no uncontrollable distractors worth filtering with an inverse model. g is an
// MLP ([D + action dim] -> hidden -> hidden -> D) predicting the change of s, trained online (Adam,
// mean squared error) on the transitions seen; transitions it predicts well earn little. The
// reward is raw_t over the running std of raw (learned.h); an autoreset step is no transition and
// earns 0.
#pragma once

#include <memory>
#include <string_view>

#include "learn/intrinsic/learned.h"

namespace cradle::learn::intrinsic {

class Icm final : public LearnedReward {
 public:
  explicit Icm(double scale = 1.0, LearnedOptions options = {}) : LearnedReward(scale, options) {}

  std::string_view name() const override { return "icm"; }

 protected:
  bool transitions() const override { return true; }
  void build(int features, int actions, at::Generator& gen) override;
  torch::Tensor score(const torch::Tensor& s, const torch::Tensor& a,
                      const torch::Tensor& next) override;
  double train_step(const std::function<Batch()>& draw) override;
  void save_models(torch::serialize::OutputArchive& archive) const override;
  void load_models(torch::serialize::InputArchive& archive) override;

 private:
  // Predicted next state s + g([s, a]).
  torch::Tensor predict(const torch::Tensor& s, const torch::Tensor& a);

  torch::nn::Sequential forward_{nullptr};
  std::unique_ptr<torch::optim::Adam> optimizer_;
};

}  // namespace cradle::learn::intrinsic

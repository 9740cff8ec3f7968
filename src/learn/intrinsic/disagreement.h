// disagreement: ensemble disagreement (after Pathak et al. 2019, "Self-Supervised Exploration via
// Disagreement").
//
//   raw_t = (1 / D) sum_j Var_k [ s_t + g_k([s_t, a_t]) ]_j
//
// K forward models g_k (MLPs [D + action dim] -> hidden -> hidden -> D, each with its own initial
// weights) predict the next normalised feature
// vector s_{t+1} (features.h); the reward is how much they disagree, averaged over the D features.
// Each model trains (Adam, mean squared error) on its own minibatches of the transitions seen, so
// the models agree where data is plentiful and differ where it is not. Unlike icm's prediction
// error, disagreement does not reward transitions that are merely unpredictable (noise): there
// every model learns the same mean. The reward is raw_t over the running std of raw (learned.h); an
// autoreset step earns 0.
#pragma once

#include <memory>
#include <string_view>
#include <vector>

#include "learn/intrinsic/learned.h"

namespace cradle::learn::intrinsic {

struct DisagreementOptions {
  LearnedOptions learned;
  int models = 5;  // ensemble size K (>= 2)
};

class Disagreement final : public LearnedReward {
 public:
  using Options = DisagreementOptions;
  explicit Disagreement(double scale = 1.0, Options options = {});

  std::string_view name() const override { return "disagreement"; }

 protected:
  bool transitions() const override { return true; }
  void build(int features, int actions, at::Generator& gen) override;
  torch::Tensor score(const torch::Tensor& s, const torch::Tensor& a,
                      const torch::Tensor& next) override;
  double train_step(const std::function<Batch()>& draw) override;
  void save_models(torch::serialize::OutputArchive& archive) const override;
  void load_models(torch::serialize::InputArchive& archive) override;

 private:
  int count_;
  std::vector<torch::nn::Sequential> models_;
  std::unique_ptr<torch::optim::Adam> optimizer_;
};

}  // namespace cradle::learn::intrinsic

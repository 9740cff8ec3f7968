// rnd: random network distillation (Burda et al. 2018) on the normalised state features.
//
//   raw_t = || f_hat(s_t) - f(s_t) ||^2 / out
//
// f is a fixed, randomly initialised MLP (features -> hidden -> hidden -> out) and f_hat a
// predictor MLP of the same shape trained (Adam, mean squared error) to match it on the states
// seen; states visited often are predicted well and earn little. s_t is the normalised feature
// vector of features.h (proprioception, pooled touch, pooled grey images); the reward is raw_t over
// the running std of raw (learned.h). Every step's observation is a sample, new episodes included.
#pragma once

#include <string_view>

#include "learn/intrinsic/learned.h"

namespace cradle::learn::intrinsic {

struct RndOptions {
  LearnedOptions learned;
  int out = 64;  // size of the random embedding
};

class Rnd final : public LearnedReward {
 public:
  using Options = RndOptions;
  explicit Rnd(double scale = 1.0, Options options = {})
      : LearnedReward(scale, options.learned), out_(options.out) {}

  std::string_view name() const override { return "rnd"; }

 protected:
  bool transitions() const override { return false; }
  void build(int features, int actions, at::Generator& gen) override;
  torch::Tensor score(const torch::Tensor& s, const torch::Tensor& a,
                      const torch::Tensor& next) override;
  double train_step(const std::function<Batch()>& draw) override;
  void save_models(torch::serialize::OutputArchive& archive) const override;
  void load_models(torch::serialize::InputArchive& archive) override;

 private:
  int out_;
  torch::nn::Sequential target_{nullptr}, predictor_{nullptr};
  std::unique_ptr<torch::optim::Adam> optimizer_;
};

}  // namespace cradle::learn::intrinsic

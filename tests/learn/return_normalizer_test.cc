// VecNormalize's return normalisation (PPO's normalize_returns): rewards end up divided by the
// standard deviation of the discounted return, autoreset steps count for nothing, and the first
// rewards (no statistics yet) are clipped at 10.
#include "learn/return_normalizer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "learn/vector_env.h"

namespace cradle::learn {
namespace {

// Pays 1 per step; episodes are truncated after 5 steps.
class FiveSteps final : public envs::Env {
 public:
  FiveSteps()
      : obs_space_{{{"observation", Box::unbounded({1}, DType::kFloat64)}}},
        action_space_(Box::uniform({1}, DType::kFloat64, -1, 1)),
        buffers_(obs_space_) {}
  const DictSpace& observation_space() const override { return obs_space_; }
  const Box& action_space() const override { return action_space_; }
  void reset(std::optional<std::uint64_t>) override { steps_ = 0; }
  envs::StepResult step(std::span<const double>) override {
    ++steps_;
    return {.reward = 1.0, .terminated = false, .truncated = steps_ >= 5};
  }
  const envs::ObservationBuffers& observation() const override { return buffers_; }
  const envs::Info& info() const override { return info_; }

 private:
  DictSpace obs_space_;
  Box action_space_;
  envs::ObservationBuffers buffers_;
  envs::Info info_;
  int steps_ = 0;
};

TEST(ReturnNormalizer, DividesByTheDiscountedReturnsStd) {
  std::vector<std::unique_ptr<envs::Env>> list;
  list.push_back(std::make_unique<FiveSteps>());
  list.push_back(std::make_unique<FiveSteps>());
  ThreadedVecEnv vec(std::move(list), 1);
  ReturnNormalizer hook(0.99);
  vec.reset(1);
  const std::vector<double> actions(2, 0.0);
  std::vector<double> rewards;
  for (int t = 0; t < 6000; ++t) {
    vec.step(actions);
    rewards.assign(vec.rewards().begin(), vec.rewards().end());
    hook(vec, actions, rewards);
    if (t == 0) {
      EXPECT_EQ(rewards[0], 10.0);  // no statistics yet: 1 / sqrt(1e-4), clipped
    }
  }
  // The discounted returns of an episode: 1, 1.99, 2.9701, ...; their population variance.
  double ret = 0, sum = 0, sum2 = 0;
  for (int k = 0; k < 5; ++k) {
    ret = 0.99 * ret + 1;
    sum += ret;
    sum2 += ret * ret;
  }
  const double var = sum2 / 5 - (sum / 5) * (sum / 5);
  // 6000 vector steps are 1000 cycles of 5 steps and an autoreset: the next is a real step.
  vec.step(actions);
  rewards.assign(vec.rewards().begin(), vec.rewards().end());
  hook(vec, actions, rewards);
  ASSERT_NE(rewards[0], 0.0);
  EXPECT_NEAR(rewards[0], 1.0 / std::sqrt(var), 2e-3);
  EXPECT_NEAR(rewards[1], 1.0 / std::sqrt(var), 2e-3);
}

}  // namespace
}  // namespace cradle::learn

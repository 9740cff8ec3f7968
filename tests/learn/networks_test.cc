// Torch thread settings of the learners: image policies update on every core, vector policies
// leave it alone unless the user sets update_threads, and the scoped change is undone.
#include "learn/networks.h"

#include <gtest/gtest.h>
#include <torch/torch.h>

#include <filesystem>
#include <set>
#include <string>
#include <thread>

#include "core/error.h"

namespace cradle::learn {
namespace {

TEST(UpdateThreads, ImagePoliciesUseEveryCoreVectorPoliciesNone) {
  const ObsShape vector_only{.vector_size = 30};
  const ObsShape with_images{.vector_size = 17, .images = {{64, 64, 3}, {64, 64, 3}}};
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  EXPECT_EQ(update_threads({}, vector_only), 0);
  EXPECT_EQ(update_threads({}, with_images), cores);
  EXPECT_EQ(update_threads({.update_threads = 3}, with_images), 3);
  EXPECT_EQ(update_threads({.update_threads = 3}, vector_only), 3);
}

TEST(UpdateThreads, ScopeSetsAndRestoresTorchThreads) {
  torch::set_num_threads(1);
  {
    const ScopedTorchThreads scope(3);
    EXPECT_EQ(torch::get_num_threads(), 3);
  }
  EXPECT_EQ(torch::get_num_threads(), 1);
  {
    const ScopedTorchThreads unchanged(0);
    EXPECT_EQ(torch::get_num_threads(), 1);
  }
  EXPECT_EQ(torch::get_num_threads(), 1);
}

// The threads of this process, by id.
std::set<std::string> thread_ids() {
  std::set<std::string> ids;
  for (const auto& entry : std::filesystem::directory_iterator("/proc/self/task")) {
    ids.insert(entry.path().filename().string());
  }
  return ids;
}

// Off-policy learners open a scope around every cycle of gradient steps: toggling it must not
// rebuild thread pools (at::set_num_threads destroyed and recreated a pool thread each time,
// which made a 2-thread SAC gradient step three times slower than a 1-thread one).
TEST(UpdateThreads, TogglingTheScopeCreatesNoThreads) {
  torch::set_num_threads(1);
  std::set<std::string> first;
  for (int i = 0; i < 10; ++i) {
    const ScopedTorchThreads scope(2);
    EXPECT_EQ(torch::get_num_threads(), 2);
    // An operation large enough for LibTorch's intra-op threads.
    EXPECT_EQ(torch::ones({1 << 20}).mul(2).sum().item<float>(), 2.0f * (1 << 20));
    if (i == 0) {
      first = thread_ids();
    } else {
      EXPECT_EQ(thread_ids(), first) << "toggle " << i;
    }
  }
}

TEST(UpdateThreads, NegativeIsAUserError) {
  EXPECT_THROW(apply_torch_options({.update_threads = -1}), UserError);
}

// Parameters of a module, counted.
long count_parameters(torch::nn::Module& m) {
  long n = 0;
  for (const auto& p : m.parameters()) n += p.numel();
  return n;
}

TEST(GaussianActorCritic, SharedTrunkFeedsPolicyAndValue) {
  const ObsShape shape{.vector_size = 5};
  auto generator = at::make_generator<at::CPUGeneratorImpl>(1);
  // Baselines' ppo2 "mlp": one trunk of 8, 6; the heads read it directly.
  PolicyConfig shared;
  shared.shared_layers = {8, 6};
  shared.pi_layers = {};
  shared.vf_layers = {};
  GaussianActorCritic net(shape, 2, shared, generator);
  // Trunk (5*8+8 + 8*6+6), action mean (6*2+2), value (6+1), log std 2.
  EXPECT_EQ(count_parameters(*net), 48 + 54 + 14 + 7 + 2);
  // Both the action mean and the value reach back into the trunk's first layer.
  ObsBatch batch = ObsBatch::zeros(shape, 3);
  batch.vector = torch::randn({3, 5}, generator);
  const auto out = net->forward(batch);
  const torch::Tensor first = net->named_parameters()["shared_net.0.weight"];
  const auto grad_of = [&](const torch::Tensor& y) {
    return torch::autograd::grad({y.sum()}, {first}, {}, true)[0].abs().sum().item<double>();
  };
  EXPECT_GT(grad_of(out.mean), 0.0);
  EXPECT_GT(grad_of(out.value), 0.0);
  EXPECT_TRUE(torch::allclose(net->value(batch), out.value));
  // Without a trunk (the default) nothing is added: separate 64-64 networks as before.
  GaussianActorCritic separate(shape, 2, PolicyConfig{}, generator);
  EXPECT_EQ(count_parameters(*separate),
            2 * (5 * 64 + 64 + 64 * 64 + 64) + (64 * 2 + 2) + (64 + 1) + 2);
  for (const auto& item : separate->named_parameters())
    EXPECT_EQ(item.key().find("shared_net"), std::string::npos);
}

}  // namespace
}  // namespace cradle::learn

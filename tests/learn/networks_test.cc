// Torch thread settings of the learners: image policies update on every core, vector policies
// leave it alone unless the user sets update_threads, and the scoped change is undone.
#include "learn/networks.h"

#include <gtest/gtest.h>
#include <torch/torch.h>

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

TEST(UpdateThreads, NegativeIsAUserError) {
  EXPECT_THROW(apply_torch_options({.update_threads = -1}), UserError);
}

}  // namespace
}  // namespace cradle::learn

// Box::sample: random values within each element's bounds, one or several boxes' worth, drawn in
// order from the generator (so a seeded run repeats them).
#include "core/spaces.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "core/rng.h"

namespace cradle {
namespace {

TEST(BoxSample, DrawsEachElementWithinItsBoundsInOrder) {
  const Box box{.shape = {3}, .low = {-1, 0, 10}, .high = {1, 0.5, 20}};
  Rng rng(4), again(4);
  std::vector<double> out(3 * 1000);  // a thousand boxes' worth, as for a vector of envs
  box.sample(rng, out);
  std::vector<double> lowest = {1e9, 1e9, 1e9}, highest = {-1e9, -1e9, -1e9};
  for (size_t k = 0; k < out.size(); ++k) {
    const size_t j = k % 3;
    ASSERT_GE(out[k], box.low[j]) << k;
    ASSERT_LT(out[k], box.high[j]) << k;
    EXPECT_EQ(out[k], again.uniform(box.low[j], box.high[j])) << k;  // the generator's order
    lowest[j] = std::min(lowest[j], out[k]);
    highest[j] = std::max(highest[j], out[k]);
  }
  // A thousand draws cover each range (not a constant or a shrunk interval).
  for (size_t j = 0; j < 3; ++j) {
    const double width = box.high[j] - box.low[j];
    EXPECT_LT(lowest[j], box.low[j] + 0.01 * width) << j;
    EXPECT_GT(highest[j], box.high[j] - 0.01 * width) << j;
  }
}

}  // namespace
}  // namespace cradle

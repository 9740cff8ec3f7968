// LibTorch helpers: tensors filled from our Rng, Xavier initialisation, rows to tensors.
#include "teach/torch_util.h"

#include <cmath>

#include "teach/gmm.h"

namespace cradle::teach {

torch::Tensor normal_tensor(Rng& rng, std::int64_t rows, std::int64_t cols) {
  torch::Tensor t = torch::empty({rows, cols});
  float* p = t.data_ptr<float>();
  for (std::int64_t i = 0; i < rows * cols; ++i) p[i] = static_cast<float>(standard_normal(rng));
  return t;
}

torch::Tensor uniform_tensor(Rng& rng, std::int64_t rows, std::int64_t cols, double lo, double hi) {
  torch::Tensor t = torch::empty({rows, cols});
  float* p = t.data_ptr<float>();
  for (std::int64_t i = 0; i < rows * cols; ++i) p[i] = static_cast<float>(rng.uniform(lo, hi));
  return t;
}

void xavier_init(torch::nn::Module& module, Rng& rng) {
  torch::NoGradGuard no_grad;
  for (auto& m : module.modules(/*include_self=*/true)) {
    auto* linear = m->as<torch::nn::Linear>();
    if (!linear) continue;
    // Uniform in +-sqrt(6 / (fan_in + fan_out)).
    const auto out = linear->weight.size(0), in = linear->weight.size(1);
    const double a = std::sqrt(6.0 / static_cast<double>(in + out));
    linear->weight.copy_(uniform_tensor(rng, out, in, -a, a));
    if (linear->bias.defined()) linear->bias.zero_();
  }
}

torch::Tensor rows_tensor(const std::vector<std::vector<float>>& rows) {
  const auto cols = rows.empty() ? 0 : static_cast<std::int64_t>(rows[0].size());
  torch::Tensor t = torch::empty({static_cast<std::int64_t>(rows.size()), cols});
  float* p = t.data_ptr<float>();
  for (const auto& r : rows)
    for (float v : r) *p++ = v;
  return t;
}

}  // namespace cradle::teach

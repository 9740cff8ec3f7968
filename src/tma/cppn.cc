#include "tma/cppn.h"

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>

#include "core/error.h"
#include "core/resources.h"

namespace cradle::tma {

Cppn::Cppn(const std::filesystem::path& file, int outputs) : outputs_(outputs) {
  const size_t count = kInputs * kHidden + 3 * kHidden * kHidden + kHidden * outputs;
  std::ifstream in(file, std::ios::binary);
  if (!in) throw UserError("CPPN weight file '" + file.string() + "' cannot be opened");
  in.seekg(0, std::ios::end);
  const auto bytes = static_cast<size_t>(in.tellg());
  if (bytes != count * sizeof(float)) {
    throw UserError("CPPN weight file '" + file.string() + "' has " + std::to_string(bytes) +
                    " bytes (expected " + std::to_string(count * sizeof(float)) + ")");
  }
  in.seekg(0);
  weights_.resize(count);
  in.read(reinterpret_cast<char*>(weights_.data()), static_cast<std::streamsize>(bytes));
}

namespace {

// y[out] = sum_i x[i] * w[i * n_out + out] (row-major [in, out]).
void dense(const float* x, int n_in, const float* w, int n_out, float* y) {
  for (int o = 0; o < n_out; ++o) y[o] = 0;
  for (int i = 0; i < n_in; ++i) {
    const float xi = x[i];
    const float* row = w + static_cast<size_t>(i) * n_out;
    for (int o = 0; o < n_out; ++o) y[o] += xi * row[o];
  }
}

// TensorFlow's softplus: log(1 + exp(x)), computed without overflow.
float softplus(float x) { return x > 0 ? x + std::log1p(std::exp(-x)) : std::log1p(std::exp(x)); }

}  // namespace

void Cppn::generate(const std::array<double, 3>& input, int points, std::vector<float>& out) const {
  out.assign(static_cast<size_t>(points) * outputs_, 0.0f);
  const float* w1 = weights_.data();
  const float* w2 = w1 + kInputs * kHidden;
  const float* w3 = w2 + kHidden * kHidden;
  const float* w4 = w3 + kHidden * kHidden;
  const float* w5 = w4 + kHidden * kHidden;
  float x[kInputs], a[kHidden], b[kHidden];
  for (int p = 0; p < points; ++p) {
    x[0] = static_cast<float>(static_cast<double>(p) / (points - 1));
    for (int k = 0; k < 3; ++k) x[k + 1] = static_cast<float>(input[k]);
    dense(x, kInputs, w1, kHidden, a);
    for (float& v : a) v = std::tanh(v);
    dense(a, kHidden, w2, kHidden, b);
    for (float& v : b) v = softplus(v);
    dense(b, kHidden, w3, kHidden, a);
    for (float& v : a) v = std::tanh(v);
    dense(a, kHidden, w4, kHidden, b);
    for (float& v : b) v = softplus(v);
    dense(b, kHidden, w5, outputs_, out.data() + static_cast<size_t>(p) * outputs_);
  }
}

std::filesystem::path data_dir() {
  std::vector<std::filesystem::path> candidates;
  if (const char* env = std::getenv("CRADLE_TMA_DATA")) candidates.emplace_back(env);
  // An installed copy uses its own data before the source tree it was built from.
  if (const auto& installed = installed_resources()) {
    candidates.push_back(*installed / "data" / "teachmyagent");
  }
  candidates.emplace_back(CRADLE_TMA_SOURCE_DATA);
  candidates.emplace_back(CRADLE_TMA_INSTALL_DATA);
  for (const auto& dir : candidates) {
    std::error_code ec;
    if (std::filesystem::exists(dir / "ground_ceiling_cppn.f32", ec)) return dir;
  }
  std::string tried;
  for (const auto& dir : candidates) tried += (tried.empty() ? "" : ", ") + dir.string();
  throw UserError("TeachMyAgent data (ground_ceiling_cppn.f32) not found in: " + tried +
                  " (set CRADLE_TMA_DATA to the data/teachmyagent folder)");
}

}  // namespace cradle::tma

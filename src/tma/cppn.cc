#include "tma/cppn.h"

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>

#include "core/error.h"
#include "core/resources.h"

namespace cradle::tma {

std::size_t Cppn::file_bytes(int inputs, int outputs) {
  const std::size_t in = static_cast<std::size_t>(inputs) + 1;
  return (in * kHidden + 3 * kHidden * kHidden + static_cast<std::size_t>(kHidden) * outputs) *
         sizeof(float);
}

namespace {

// The file holding the weights: `path` itself, or the data file of a TensorFlow checkpoint prefix.
std::filesystem::path weight_file(const std::filesystem::path& path) {
  std::error_code ec;
  if (std::filesystem::is_regular_file(path, ec)) return path;
  const std::filesystem::path data = path.string() + ".data-00000-of-00001";
  if (std::filesystem::is_regular_file(data, ec)) return data;
  if (std::filesystem::is_directory(path, ec)) {
    const std::filesystem::path inside = path / ".data-00000-of-00001";
    if (std::filesystem::is_regular_file(inside, ec)) return inside;
  }
  throw UserError("CPPN weight file '" + path.string() +
                  "' not found (expected a raw float32 weight file or a TensorFlow checkpoint "
                  "prefix with its .data-00000-of-00001 file)");
}

}  // namespace

Cppn::Cppn(const std::filesystem::path& path, int outputs, int inputs)
    : inputs_(inputs), outputs_(outputs) {
  if (inputs < 1 || outputs < 1) {
    throw UserError("CPPN sizes " + std::to_string(inputs) + " inputs, " + std::to_string(outputs) +
                    " outputs (expected >= 1 each)");
  }
  const std::filesystem::path file = weight_file(path);
  std::ifstream in(file, std::ios::binary);
  if (!in) throw UserError("CPPN weight file '" + file.string() + "' cannot be opened");
  in.seekg(0, std::ios::end);
  const auto bytes = static_cast<std::size_t>(in.tellg());
  const std::size_t expected = file_bytes(inputs, outputs);
  if (bytes != expected) {
    throw UserError("CPPN weight file '" + file.string() + "' has " + std::to_string(bytes) +
                    " bytes (expected " + std::to_string(expected) + " for " +
                    std::to_string(inputs) + " inputs and " + std::to_string(outputs) +
                    " outputs: float32 layers " + std::to_string(inputs + 1) +
                    "x64, 3 x 64x64, 64x" + std::to_string(outputs) + ")");
  }
  in.seekg(0);
  weights_.resize(expected / sizeof(float));
  in.read(reinterpret_cast<char*>(weights_.data()), static_cast<std::streamsize>(bytes));
  if (!in) throw UserError("CPPN weight file '" + file.string() + "' cannot be read");
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

void Cppn::generate(std::span<const double> input, int points, std::vector<float>& out) const {
  if (static_cast<int>(input.size()) != inputs_) {
    throw UserError("CPPN input vector has " + std::to_string(input.size()) + " values (expected " +
                    std::to_string(inputs_) + ", the CPPN's input dimension)");
  }
  out.assign(static_cast<size_t>(points) * outputs_, 0.0f);
  const int n_in = inputs_ + 1;
  const float* w1 = weights_.data();
  const float* w2 = w1 + static_cast<size_t>(n_in) * kHidden;
  const float* w3 = w2 + kHidden * kHidden;
  const float* w4 = w3 + kHidden * kHidden;
  const float* w5 = w4 + kHidden * kHidden;
  std::vector<float> x(n_in);
  float a[kHidden], b[kHidden];
  for (int k = 0; k < inputs_; ++k) x[k + 1] = static_cast<float>(input[k]);
  for (int p = 0; p < points; ++p) {
    x[0] = static_cast<float>(static_cast<double>(p) / (points - 1));
    dense(x.data(), n_in, w1, kHidden, a);
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

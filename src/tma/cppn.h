// The Parkour terrain CPPN (TanHSoftplusMixCPPN): a bias-free MLP 4 -> 64 tanh -> 64 softplus ->
// 64 tanh -> 64 softplus -> outputs, evaluated in float32 as TensorFlow does, from the shipped
// weight file (plain little-endian float32, row-major [in, out], layers in order).
#pragma once

#include <array>
#include <filesystem>
#include <span>
#include <vector>

namespace cradle::tma {

class Cppn {
 public:
  static constexpr int kInputs = 4, kHidden = 64;
  // Loads `file` with `outputs` output columns; throws cradle::UserError if the file is missing or
  // has the wrong size.
  Cppn(const std::filesystem::path& file, int outputs);
  int outputs() const { return outputs_; }
  // Outputs at the `points` positions x = i / (points - 1) for the 3-D input vector:
  // out[i * outputs + k].
  void generate(const std::array<double, 3>& input, int points, std::vector<float>& out) const;

 private:
  int outputs_;
  std::vector<float> weights_;  // layers concatenated
};

// The folder holding the TeachMyAgent data files: $CRADLE_TMA_DATA if set, else the source tree's
// data/teachmyagent, else the install's share/cradle/teachmyagent. Throws if none exists.
std::filesystem::path data_dir();

}  // namespace cradle::tma

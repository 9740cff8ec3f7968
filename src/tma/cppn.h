// The Parkour terrain CPPN (TanHSoftplusMixCPPN): a bias-free MLP (1 + input dim) -> 64 tanh -> 64
// softplus -> 64 tanh -> 64 softplus -> outputs, evaluated in float32 as TensorFlow does, from a
// weight file of plain little-endian float32, row-major [in, out], layers in order (the shipped
// data/teachmyagent/ground_ceiling_cppn.f32). The reference's TensorFlow checkpoint stores the same
// bytes in its .data-00000-of-00001 file (variables Variable, Variable_1 ... Variable_4 are the
// layers in order, no padding), so a checkpoint prefix is read through that file.
#pragma once

#include <filesystem>
#include <span>
#include <vector>

namespace cradle::tma {

class Cppn {
 public:
  static constexpr int kHidden = 64;
  // Loads `file` with `inputs` task inputs (the x position is one more) and `outputs` output
  // columns. `file` is a raw weight file, or a TensorFlow checkpoint prefix (a folder ending in
  // '/' as the reference passes it, or a path P with P.data-00000-of-00001 next to it). Throws
  // cradle::UserError if no file is found or its size does not fit the layer sizes.
  Cppn(const std::filesystem::path& file, int outputs, int inputs = 3);
  int inputs() const { return inputs_; }
  int outputs() const { return outputs_; }
  // Outputs at the `points` positions x = i / (points - 1) for the task's input vector (inputs()
  // values): out[i * outputs + k].
  void generate(std::span<const double> input, int points, std::vector<float>& out) const;
  // Size in bytes of a weight file for these layer sizes.
  static std::size_t file_bytes(int inputs, int outputs);

 private:
  int inputs_, outputs_;
  std::vector<float> weights_;  // layers concatenated
};

// The folder holding the TeachMyAgent data files: $CRADLE_TMA_DATA if set, else the source tree's
// data/teachmyagent, else the install's share/cradle/teachmyagent. Throws if none exists.
std::filesystem::path data_dir();

}  // namespace cradle::tma

// Observation and action spaces, Gymnasium-shaped: a Box has a shape, a dtype and bounds; a Dict
// maps observation keys to Boxes in a fixed order.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace cradle {

class Rng;

enum class DType { kFloat32, kFloat64, kUInt8 };
std::string_view dtype_name(DType dtype);  // "float32", "float64", "uint8"
int dtype_size(DType dtype);               // bytes per element

struct Box {
  std::vector<int> shape;
  DType dtype = DType::kFloat64;
  std::vector<double> low;   // one bound per element
  std::vector<double> high;  // one bound per element

  int size() const;  // product of the shape
  // A box with the same bounds for every element (±infinity for unbounded).
  static Box uniform(std::vector<int> shape, DType dtype, double low, double high);
  static Box unbounded(std::vector<int> shape, DType dtype) {
    return uniform(std::move(shape), dtype, -std::numeric_limits<double>::infinity(),
                   std::numeric_limits<double>::infinity());
  }
  // Uniform random values within the bounds (finite ones) from `rng`, element by element: `out`
  // holds one or several boxes' worth (value k within bound k mod size()), as random actions for
  // one env or a vector of them.
  void sample(Rng& rng, std::span<double> out) const;
  friend bool operator==(const Box&, const Box&) = default;
};

struct DictSpace {
  std::vector<std::pair<std::string, Box>> entries;  // in observation order
  const Box* find(std::string_view key) const;
  friend bool operator==(const DictSpace&, const DictSpace&) = default;
};

}  // namespace cradle

#include "core/spaces.h"

#include "core/rng.h"

namespace cradle {

std::string_view dtype_name(DType dtype) {
  switch (dtype) {
    case DType::kFloat32:
      return "float32";
    case DType::kFloat64:
      return "float64";
    case DType::kUInt8:
      return "uint8";
  }
  return "float64";
}

int dtype_size(DType dtype) {
  switch (dtype) {
    case DType::kFloat32:
      return 4;
    case DType::kFloat64:
      return 8;
    case DType::kUInt8:
      return 1;
  }
  return 8;
}

int Box::size() const {
  int n = 1;
  for (int s : shape) n *= s;
  return n;
}

Box Box::uniform(std::vector<int> shape, DType dtype, double low, double high) {
  Box box{.shape = std::move(shape), .dtype = dtype};
  box.low.assign(box.size(), low);
  box.high.assign(box.size(), high);
  return box;
}

void Box::sample(Rng& rng, std::span<double> out) const {
  const size_t n = low.size();
  for (size_t k = 0; k < out.size(); ++k) out[k] = rng.uniform(low[k % n], high[k % n]);
}

const Box* DictSpace::find(std::string_view key) const {
  for (const auto& [name, box] : entries) {
    if (name == key) return &box;
  }
  return nullptr;
}

}  // namespace cradle

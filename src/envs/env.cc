#include "envs/env.h"

#include <cstdint>
#include <cstring>
#include <limits>
#include <stdexcept>

#include "core/error.h"

namespace cradle::envs {

namespace {
// An entry's bytes rounded up to whole max_align_t: every entry starts on such a boundary, so
// typed views are always aligned.
size_t padded(size_t bytes) {
  return (bytes + sizeof(std::max_align_t) - 1) / sizeof(std::max_align_t) *
         sizeof(std::max_align_t);
}

// The entries' offsets and sizes (bytes) and dtypes in one block of bytes_needed(space).
void lay_out(const DictSpace& space, std::vector<size_t>& offsets, std::vector<size_t>& sizes,
             std::vector<DType>& dtypes) {
  size_t offset = 0;
  for (const auto& [key, box] : space.entries) {
    const size_t bytes = static_cast<size_t>(box.size()) * dtype_size(box.dtype);
    offsets.push_back(offset);
    sizes.push_back(bytes);
    dtypes.push_back(box.dtype);
    offset += padded(bytes);
  }
}
}  // namespace

ObservationBuffers::ObservationBuffers(const DictSpace& space) {
  lay_out(space, offsets_, sizes_, dtypes_);
  storage_.resize(bytes_needed(space) / sizeof(std::max_align_t));
  // Value-initialising max_align_t zeroes its members, not its padding (the bytes after the
  // long double's 10): zero every byte so an entry nobody wrote reads 0, not stale heap.
  std::memset(storage_.data(), 0, storage_.size() * sizeof(std::max_align_t));
}

ObservationBuffers::ObservationBuffers(const DictSpace& space, std::span<std::byte> storage) {
  if (storage.size() < bytes_needed(space) ||
      reinterpret_cast<std::uintptr_t>(storage.data()) % alignof(std::max_align_t) != 0) {
    throw std::invalid_argument("ObservationBuffers: storage too small or misaligned");
  }
  lay_out(space, offsets_, sizes_, dtypes_);
  external_ = storage.data();
}

size_t ObservationBuffers::bytes_needed(const DictSpace& space) {
  size_t total = 0;
  for (const auto& [key, box] : space.entries) {
    total += padded(static_cast<size_t>(box.size()) * dtype_size(box.dtype));
  }
  return total + sizeof(std::max_align_t);
}

std::byte* ObservationBuffers::base() {
  return external_ ? external_ : reinterpret_cast<std::byte*>(storage_.data());
}
const std::byte* ObservationBuffers::base() const {
  return external_ ? external_ : reinterpret_cast<const std::byte*>(storage_.data());
}

namespace {
template <typename T, typename Byte>
std::span<T> view(Byte* base, size_t offset, size_t bytes) {
  return {reinterpret_cast<T*>(base + offset), bytes / sizeof(T)};
}
}  // namespace

std::span<double> ObservationBuffers::f64(int i) {
  return view<double>(base(), offsets_[i], sizes_[i]);
}
std::span<float> ObservationBuffers::f32(int i) {
  return view<float>(base(), offsets_[i], sizes_[i]);
}
std::span<std::uint8_t> ObservationBuffers::u8(int i) {
  return view<std::uint8_t>(base(), offsets_[i], sizes_[i]);
}
std::span<const double> ObservationBuffers::f64(int i) const {
  return view<const double>(base(), offsets_[i], sizes_[i]);
}
std::span<const float> ObservationBuffers::f32(int i) const {
  return view<const float>(base(), offsets_[i], sizes_[i]);
}
std::span<const std::uint8_t> ObservationBuffers::u8(int i) const {
  return view<const std::uint8_t>(base(), offsets_[i], sizes_[i]);
}
std::span<const std::byte> ObservationBuffers::bytes(int i) const {
  return view<const std::byte>(base(), offsets_[i], sizes_[i]);
}

void Env::set_reset_options(const ResetOptions& options) {
  if (!options.empty()) {
    throw UserError("reset option '" + options.begin()->first + "' is not one this env takes");
  }
}

double Env::score() const { return std::numeric_limits<double>::quiet_NaN(); }

const ObservationLayout* Env::layout(std::string_view) const { return nullptr; }

}  // namespace cradle::envs

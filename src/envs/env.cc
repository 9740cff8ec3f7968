#include "envs/env.h"

#include <cstring>
#include <limits>

#include "core/error.h"

namespace cradle::envs {

ObservationBuffers::ObservationBuffers(const DictSpace& space) {
  size_t total = 0;
  for (const auto& [key, box] : space.entries) {
    // Every entry starts on a max_align_t boundary, so typed views are always aligned.
    offsets_.push_back(total);
    const size_t bytes = static_cast<size_t>(box.size()) * dtype_size(box.dtype);
    sizes_.push_back(bytes);
    dtypes_.push_back(box.dtype);
    total += (bytes + sizeof(std::max_align_t) - 1) / sizeof(std::max_align_t) *
             sizeof(std::max_align_t);
  }
  storage_.resize(total / sizeof(std::max_align_t) + 1);
  // Value-initialising max_align_t zeroes its members, not its padding (the bytes after the
  // long double's 10): zero every byte so an entry nobody wrote reads 0, not stale heap.
  std::memset(storage_.data(), 0, storage_.size() * sizeof(std::max_align_t));
}

namespace {
template <typename T, typename Storage>
std::span<T> view(Storage& storage, size_t offset, size_t bytes) {
  auto* base =
      reinterpret_cast<std::conditional_t<std::is_const_v<T>, const std::byte, std::byte>*>(
          storage.data());
  return {reinterpret_cast<T*>(base + offset), bytes / sizeof(T)};
}
}  // namespace

std::span<double> ObservationBuffers::f64(int i) {
  return view<double>(storage_, offsets_[i], sizes_[i]);
}
std::span<float> ObservationBuffers::f32(int i) {
  return view<float>(storage_, offsets_[i], sizes_[i]);
}
std::span<std::uint8_t> ObservationBuffers::u8(int i) {
  return view<std::uint8_t>(storage_, offsets_[i], sizes_[i]);
}
std::span<const double> ObservationBuffers::f64(int i) const {
  return view<const double>(storage_, offsets_[i], sizes_[i]);
}
std::span<const float> ObservationBuffers::f32(int i) const {
  return view<const float>(storage_, offsets_[i], sizes_[i]);
}
std::span<const std::uint8_t> ObservationBuffers::u8(int i) const {
  return view<const std::uint8_t>(storage_, offsets_[i], sizes_[i]);
}
std::span<const std::byte> ObservationBuffers::bytes(int i) const {
  return view<const std::byte>(storage_, offsets_[i], sizes_[i]);
}

void Env::set_reset_options(const ResetOptions& options) {
  if (!options.empty()) {
    throw UserError("reset option '" + options.begin()->first + "' is not one this env takes");
  }
}

double Env::score() const { return std::numeric_limits<double>::quiet_NaN(); }

const ObservationLayout* Env::layout(std::string_view) const { return nullptr; }

}  // namespace cradle::envs

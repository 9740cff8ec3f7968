#include "envs/env.h"

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

nlohmann::json Info::to_json(Behavior behavior) const {
  nlohmann::json j;
  if (behavior == Behavior::kSelfTouch) {
    j["right_hand_touches"] = right_hand_touches;
    j["left_hand_touches"] = left_hand_touches;
  } else if (behavior == Behavior::kHandRegard) {
    j["right_eye_right_hand"] = hand_regard[0];
    j["right_eye_left_hand"] = hand_regard[1];
    j["left_eye_right_hand"] = hand_regard[2];
    j["left_eye_left_hand"] = hand_regard[3];
    j["right_eye_either_hand"] = hand_regard_either[0];
    j["left_eye_either_hand"] = hand_regard_either[1];
  }
  j["steps"] = steps;
  return j;
}

}  // namespace cradle::envs

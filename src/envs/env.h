// The environment interface (Gymnasium-shaped, EnvPool-style): spaces plus reset/step writing
// observations into preallocated buffers that the caller reads as typed views.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "core/config.h"
#include "core/spaces.h"

namespace cradle::envs {

// Contiguous storage for a DictSpace: one aligned block, one typed view per key.
class ObservationBuffers {
 public:
  explicit ObservationBuffers(const DictSpace& space);
  int count() const { return static_cast<int>(offsets_.size()); }
  std::span<double> f64(int index);
  std::span<float> f32(int index);
  std::span<std::uint8_t> u8(int index);
  std::span<const double> f64(int index) const;
  std::span<const float> f32(int index) const;
  std::span<const std::uint8_t> u8(int index) const;
  // Raw bytes of one entry (for copying into batches or numpy arrays).
  std::span<const std::byte> bytes(int index) const;

 private:
  std::vector<std::max_align_t> storage_;
  std::vector<size_t> offsets_, sizes_;  // bytes
  std::vector<DType> dtypes_;
};

// Per-step information. Behaviours fill their own fields; `steps` is always set.
struct Info {
  int steps = 0;  // env steps in this episode before this one (0 on the first step)
  // MIMo sample envs: the task's success and failure flags of the last step.
  bool is_success = false, is_failure = false;
  // Self-touch: MIMo geom ids touched by each hand since reset, in order of first contact.
  std::vector<int> right_hand_touches, left_hand_touches;
  // Hand regard: steps with each hand in the central field of view of each eye.
  std::array<int, 4> hand_regard{};  // right_eye_right_hand, right_eye_left_hand,
                                     // left_eye_right_hand, left_eye_left_hand
  // Hand regard, Cradle extra: steps with either hand in view of the right / left eye.
  std::array<int, 2> hand_regard_either{};
  // The reference's info dict for the behaviour (plus Cradle's extra keys), with `steps`.
  nlohmann::json to_json(Behavior behavior) const;
};

struct StepResult {
  double reward = 0;
  bool terminated = false;
  bool truncated = false;
};

class Env {
 public:
  virtual ~Env() = default;
  virtual const DictSpace& observation_space() const = 0;
  virtual const Box& action_space() const = 0;
  // Starts an episode; a seed reseeds the env's generator, no seed continues its stream.
  virtual void reset(std::optional<std::uint64_t> seed = std::nullopt) = 0;
  virtual StepResult step(std::span<const double> action) = 0;
  virtual const ObservationBuffers& observation() const = 0;
  virtual const Info& info() const = 0;
};

}  // namespace cradle::envs

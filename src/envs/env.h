// The environment interface (Gymnasium-shaped, EnvPool-style): spaces plus reset/step writing
// observations into preallocated buffers that the caller reads as typed views.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/spaces.h"
#include "envs/info.h"

namespace cradle::envs {

// Contiguous storage for a DictSpace: one aligned block, one typed view per key.
class ObservationBuffers {
 public:
  explicit ObservationBuffers(const DictSpace& space);
  // Views over `storage` that someone else owns (at least bytes_needed(space) bytes, aligned to
  // max_align_t), e.g. shared memory that a process vector's worker writes.
  ObservationBuffers(const DictSpace& space, std::span<std::byte> storage);
  static size_t bytes_needed(const DictSpace& space);
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
  std::byte* base();
  const std::byte* base() const;

  std::vector<std::max_align_t> storage_;
  std::byte* external_ = nullptr;        // borrowed storage, when given
  std::vector<size_t> offsets_, sizes_;  // bytes
  std::vector<DType> dtypes_;
};

// Structure an observation key publishes: `values_per_item` consecutive values per item (e.g. 3
// force components per touch sensor) and named groupings of the items (group id per item, e.g.
// the "geom" and "body" each skin sensor sits on), so learners pool without knowing the sense.
struct ObservationLayout {
  int values_per_item = 1;
  std::map<std::string, std::vector<int>, std::less<>> groups;
};

// Options an env applies at every later reset (randomized starts, a teacher's task parameters).
using ResetOptions = std::map<std::string, double, std::less<>>;

// A reset option a teacher can set, with the range the env accepts (envs/registry.h lists each
// env's).
struct TaskParameter {
  std::string name;
  double low = 0, high = 0;
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

  // Takes options for the following resets; throws UserError for one the env does not take (this
  // default takes none).
  virtual void set_reset_options(const ResetOptions& options);
  // Ends the run: records what the env logs (the last, partial episode). Idempotent.
  virtual void close() {}
  // The task's score of the episode so far (NaN when the task has none).
  virtual double score() const;
  // The structure an observation key publishes (nullptr: none).
  virtual const ObservationLayout* layout(std::string_view key) const;
};

}  // namespace cradle::envs

// The compact state vector that the learned rewards (rnd, icm, disagreement) see, and the running
// statistics that normalise it and their rewards. Not a reward itself.
//
// Features of one env's observation, in observation order:
//   every float64 / float32 entry except "touch" (proprioception, vestibular): copied as is;
//   "touch": pooled per sensing body (the "body" grouping of the layout the env publishes for
//     it; per contiguous chunk of touch_chunks equal parts when it publishes none):
//     log(1 + sum of |value| over the body's entries);
//   every uint8 image {H, W, 3}: grey (mean of R, G, B) / 255, averaged over an
//     image_cells x image_cells grid of blocks.
// A RunningNorm then standardises each feature: (x - mean) / sqrt(var + 1e-8), clipped to
// [-clip, clip], with mean and var over every sample seen so far.
#pragma once

#include <nlohmann/json.hpp>
#include <span>
#include <vector>

#include "learn/vec_env.h"

namespace cradle::learn::intrinsic {

class Features {
 public:
  struct Options {
    bool proprio = true;    // float entries other than touch
    bool touch = true;      // pooled touch
    bool images = true;     // pooled grey images
    int image_cells = 8;    // image grid: cells per side
    int touch_chunks = 64;  // touch groups when the sensing bodies are unknown
  };
  Features() = default;
  Features(const VecEnv& env, Options options);

  int size() const { return size_; }
  // Writes env i's features (size() values) into out.
  void extract(const VecEnv& env, int i, std::span<float> out) const;

 private:
  enum class Kind { kCopy, kTouch, kImage };
  struct Part {
    Kind kind;
    int key;
    DType dtype;
    int height = 0, width = 0;  // images
  };
  Options options_;
  std::vector<Part> parts_;
  std::vector<std::pair<int, int>> touch_ranges_;  // [begin, end) entries of each touch group
  int size_ = 0;
};

// Per-feature running mean and variance (Chan et al.'s parallel update, in double).
class RunningNorm {
 public:
  RunningNorm() = default;
  RunningNorm(int size, double clip) : mean_(size, 0), m2_(size, 0), clip_(clip) {}
  // Adds rows (rows x size, row-major) to the statistics.
  void update(std::span<const float> rows);
  // Standardises rows in place with the current statistics.
  void apply(std::span<float> rows) const;
  double count() const { return count_; }
  nlohmann::json to_json() const;
  void from_json(const nlohmann::json& j);

 private:
  std::vector<double> mean_, m2_;
  double count_ = 0;
  double clip_ = 5;
};

// Running standard deviation of a scalar stream (Welford), used to bring a reward to unit scale.
class RunningStd {
 public:
  void update(double x);
  // x / std (x itself until two samples are in).
  double scale(double x) const;
  double std() const;
  nlohmann::json to_json() const { return {count_, mean_, m2_}; }
  void from_json(const nlohmann::json& j) {
    count_ = j.at(0).get<double>();
    mean_ = j.at(1).get<double>();
    m2_ = j.at(2).get<double>();
  }

 private:
  double count_ = 0, mean_ = 0, m2_ = 0;
};

}  // namespace cradle::learn::intrinsic

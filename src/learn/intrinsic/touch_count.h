// touch_count: the reference's example self-touch reward (examples/intrinsic_selftouch_count.py).
//
//   r_t = |{ k : touch_t[k] > threshold }| / K
//
// over the flattened touch observation touch_t (K entries: 3 per sensor with force_vector, 1 with
// normal), i.e. the fraction of active touch entries. Negative force components never count, as in
// the reference. Stateless.
#pragma once

#include <span>
#include <string_view>

#include "learn/intrinsic/reward.h"

namespace cradle::learn::intrinsic {

struct TouchCountOptions {
  double threshold = 1e-6;  // an entry counts when strictly above this (the reference's 1e-6)
};

class TouchCount final : public IntrinsicReward {
 public:
  using Options = TouchCountOptions;
  explicit TouchCount(double scale = 1.0, Options options = {})
      : IntrinsicReward(scale), options_(options) {}

  std::string_view name() const override { return "touch_count"; }
  // Throws UserError when the vector has no "touch" observation.
  void bind(const VecEnv& env) override;
  void compute(const VecEnv& env, std::span<const double> actions,
               std::span<double> rewards) override;

  // The reward of one touch vector (unscaled).
  static double of(std::span<const float> touch, double threshold = 1e-6);

 private:
  Options options_;
  int touch_key_ = -1;
};

}  // namespace cradle::learn::intrinsic

#include "learn/hyperparam_ranges.h"

#include <charconv>
#include <cmath>
#include <limits>
#include <string>

#include "core/error.h"

namespace cradle::learn {
namespace {

// lo <= value <= hi, or lo < value when low_open (positive quantities).
struct Range {
  std::string_view name;
  double lo, hi;
  bool low_open = false;
};

constexpr double kBig = 1e9;

// Every learner's numeric settings; units as in their docs (PpoConfig, A2cConfig, SacConfig, ...).
constexpr Range kRanges[] = {
    {"learning_rate", 0, 1, true},
    {"adam_eps", 0, 1, true},
    {"rms_prop_eps", 0, 1, true},
    {"rms_prop_alpha", 0, 1},
    {"n_steps", 1, 1e6},
    {"batch_size", 1, 1e7},
    {"n_epochs", 1, 1000},
    {"gamma", 0, 1},
    {"gae_lambda", 0, 1},
    {"clip_range", 0, 10, true},
    {"clip_range_vf", -kBig, 1e3},  // <= 0: off
    {"ent_coef", 0, 1e3},
    {"vf_coef", 0, 1e3},
    {"max_grad_norm", 0, 1e6, true},
    {"target_kl", -kBig, 1e3},  // <= 0: off
    {"log_std_init", -20, 5},
    {"clip_observations", 0, 1e6, true},
    {"buffer_size", 1, 1e9},
    {"learning_starts", 0, 1e11},
    {"tau", 0, 1, true},
    {"train_freq", 1, 1e6},
    {"gradient_steps", 1, 1e4},
    {"policy_delay", 1, 1e4},
    {"target_update_interval", 1, 1e6},
    {"exploration_noise", 0, 1e3},
    {"target_policy_noise", 0, 1e3},
    {"target_noise_clip", 0, 1e3},
    {"target_entropy", -1e6, 1e6},
    {"n_critics", 1, 100},
    {"report_every", 1, 1e11},
    {"shared_layers", 1, 65536},
    {"pi_layers", 1, 65536},
    {"vf_layers", 1, 65536},
    {"qf_layers", 1, 65536},
    {"cnn_features", 1, 65536},
};

std::string text(double v) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), v);
  return std::string(buffer, result.ptr);
}

}  // namespace

void check_hyperparameter_range(std::string_view name, double value) {
  const std::string prefix = "hyperparameter '" + std::string(name) + "' = " + text(value) + ": ";
  if (!std::isfinite(value)) throw UserError(prefix + "expected a finite number");
  for (const Range& r : kRanges) {
    if (r.name != name) continue;
    const bool ok = (r.low_open ? value > r.lo : value >= r.lo) && value <= r.hi;
    if (!ok) {
      throw UserError(prefix + "expected " + text(r.lo) + (r.low_open ? " < " : " <= ") +
                      std::string(name) + " <= " + text(r.hi));
    }
    return;
  }
}

}  // namespace cradle::learn

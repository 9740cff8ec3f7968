// Shared teacher plumbing: bound checks, uniform draws, clipping, JSON dump.
#include "teach/teacher.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "core/error.h"
#include "teach/gmm.h"

namespace cradle::teach {
namespace {

// A value as users write it (1e+170, nan, -inf), not std::to_string's 171 digits.
std::string text(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

// Throws UserError naming `what` unless every value is finite and within kMaxAbsReturn.
template <typename T>
void check_values(const std::vector<T>& values, const std::string& what) {
  for (std::size_t i = 0; i < values.size(); ++i)
    if (!(std::abs(static_cast<double>(values[i])) <= kMaxAbsReturn))
      throw UserError("teacher: " + what + " value " + std::to_string(i) + " is " +
                      text(values[i]) +
                      "; expected finite values of magnitude <= " + text(kMaxAbsReturn));
}

}  // namespace

Teacher::Teacher(std::vector<float> mins, std::vector<float> maxs, std::uint64_t seed)
    : mins_(std::move(mins)), maxs_(std::move(maxs)), rng_(seed) {
  // Reject malformed boxes up front: every teacher relies on them.
  if (mins_.empty())
    throw UserError("teacher: task bounds are empty; expected at least 1 dimension");
  if (mins_.size() != maxs_.size())
    throw UserError("teacher: " + std::to_string(mins_.size()) + " mins but " +
                    std::to_string(maxs_.size()) + " maxs; expected the same count");
  for (std::size_t i = 0; i < mins_.size(); ++i) {
    if (!std::isfinite(mins_[i]) || !std::isfinite(maxs_[i]) || mins_[i] > maxs_[i])
      throw UserError("teacher: bounds of dimension " + std::to_string(i) + " are [" +
                      std::to_string(mins_[i]) + ", " + std::to_string(maxs_[i]) +
                      "]; expected finite min <= max");
  }
}

Task Teacher::uniform_task() {
  Task task(mins_.size());
  for (std::size_t i = 0; i < task.size(); ++i)
    task[i] = static_cast<float>(rng_.uniform(mins_[i], maxs_[i]));
  clip(task);  // float rounding can land exactly on max + ulp
  return task;
}

void Teacher::clip(Task& task) const {
  for (std::size_t i = 0; i < task.size(); ++i) task[i] = std::clamp(task[i], mins_[i], maxs_[i]);
}

Task Teacher::gaussian_task(const DiagGaussian& dist) {
  Task task(mins_.size());
  for (std::size_t i = 0; i < task.size(); ++i)
    task[i] = static_cast<float>(dist.mean[i] + std::sqrt(static_cast<double>(dist.variance[i])) *
                                                    standard_normal(rng_));
  clip(task);
  return task;
}

DiagGaussian Teacher::dist_from_bounds(bool subspace) {
  DiagGaussian g;
  for (std::size_t i = 0; i < mins_.size(); ++i) {
    const double range = static_cast<double>(maxs_[i]) - mins_[i];
    const double mean = subspace ? rng_.uniform(mins_[i], maxs_[i]) : mins_[i] + range / 2;
    const double std = subspace ? 0.1 * range : range / 4;
    g.mean.push_back(static_cast<float>(mean));
    g.variance.push_back(std == 0 ? 1e-6f : static_cast<float>(std * std));
  }
  return g;
}

void Teacher::check_dist(const DiagGaussian& dist, const std::string& what) const {
  // Sizes first, then values: the message names the first fault.
  if (dist.mean.size() != mins_.size() || dist.variance.size() != mins_.size())
    throw UserError(what + ": mean has " + std::to_string(dist.mean.size()) + " and variance " +
                    std::to_string(dist.variance.size()) + " values; expected " +
                    std::to_string(mins_.size()) + " each (the task dimensions)");
  for (std::size_t i = 0; i < mins_.size(); ++i)
    if (!std::isfinite(dist.mean[i]) || !std::isfinite(dist.variance[i]) || dist.variance[i] < 0)
      throw UserError(what + ": dimension " + std::to_string(i) +
                      " has a non-finite mean or a negative variance; expected finite, >= 0");
}

void Teacher::check_episode(const Task& task, double ret) const {
  // A GMM or a network fitted on a NaN, or on a task read past its end, is garbage from then on:
  // refuse the episode before any book-keeping changes.
  if (task.size() != mins_.size())
    throw UserError("teacher: episode task has " + std::to_string(task.size()) +
                    " values; expected " + std::to_string(mins_.size()) + " (the task dimensions)");
  check_values(task, "episode task");
  if (!(std::abs(ret) <= kMaxAbsReturn))
    throw UserError("teacher: episode return is " + text(ret) +
                    "; expected a finite return of magnitude <= " + text(kMaxAbsReturn));
}

void Teacher::check_initial_state(const Task& task, const std::vector<float>& s0) const {
  if (task.size() != mins_.size())
    throw UserError("teacher: initial-state task has " + std::to_string(task.size()) +
                    " values; expected " + std::to_string(mins_.size()) + " (the task dimensions)");
  check_values(task, "initial-state task");
  check_values(s0, "initial state");
}

void Teacher::check_step(const std::vector<float>& s, const std::vector<float>& a, double r,
                         const std::vector<float>& s_next) const {
  if (!(std::abs(r) <= kMaxAbsReturn))
    throw UserError("teacher: step reward is " + text(r) +
                    "; expected a finite reward of magnitude <= " + text(kMaxAbsReturn));
  check_values(s, "step state");
  check_values(a, "step action");
  check_values(s_next, "step next state");
}

void Teacher::record_initial_state(const Task& task, const std::vector<float>& s0) {
  check_initial_state(task, s0);
}

void Teacher::step_update(const std::vector<float>& s, const std::vector<float>& a, double r,
                          const std::vector<float>& s_next, bool /*done*/) {
  check_step(s, a, r, s_next);
}

nlohmann::json Teacher::dump() const {
  return {{"teacher", name()}, {"mins", mins_}, {"maxs", maxs_}};
}

}  // namespace cradle::teach

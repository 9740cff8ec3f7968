// Shared teacher plumbing: bound checks, uniform draws, clipping, JSON dump.
#include "teach/teacher.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"
#include "teach/gmm.h"

namespace cradle::teach {

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

nlohmann::json Teacher::dump() const {
  return {{"teacher", name()}, {"mins", mins_}, {"maxs", maxs_}};
}

}  // namespace cradle::teach

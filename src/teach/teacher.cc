// Shared teacher plumbing: bound checks, uniform draws, clipping, JSON dump.
#include "teach/teacher.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"

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

nlohmann::json Teacher::dump() const {
  return {{"teacher", name()}, {"mins", mins_}, {"maxs", maxs_}};
}

}  // namespace cradle::teach

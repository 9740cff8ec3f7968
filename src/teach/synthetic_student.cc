// The synthetic student: competence per grid cell, grown only by practice next to what is known.
#include "teach/synthetic_student.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"
#include "teach/gmm.h"

namespace cradle::teach {

SyntheticStudent::SyntheticStudent(SyntheticStudentOptions options, std::uint64_t seed)
    : o_(options), rng_(seed) {
  // Check the options before sizing anything by them.
  if (o_.cells < 1 || o_.learnable_columns < 1 || o_.learnable_columns > o_.cells)
    throw UserError("synthetic student: cells must be >= 1 and learnable_columns in 1..cells");
  if (!(o_.gain > 0 && o_.gain <= 1) || !(o_.mastery > 0 && o_.mastery <= 1))
    throw UserError("synthetic student: gain and mastery must lie in (0, 1]");
  competence_.assign(static_cast<std::size_t>(o_.cells) * o_.cells, 0.0);
  competence_[0] = 1.0;  // the corner cell (0, 0) is mastered from the start
}

bool SyntheticStudent::mastered(double c) const { return c >= o_.mastery - 1e-9; }

int SyntheticStudent::cell_of(float x) const {
  return std::clamp(static_cast<int>(std::floor(x * o_.cells)), 0, o_.cells - 1);
}

bool SyntheticStudent::can_learn(int cx, int cy) const {
  // Learnable columns only, and only next to (or in) a cell already under way.
  if (cx >= o_.learnable_columns) return false;
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const int x = cx + dx, y = cy + dy;
      if (x < 0 || y < 0 || x >= o_.cells || y >= o_.cells) continue;
      const double c = competence_[static_cast<std::size_t>(y) * o_.cells + x];
      if ((dx == 0 && dy == 0 && c > 0) || mastered(c)) return true;
    }
  return false;
}

std::pair<double, bool> SyntheticStudent::play(const Task& task) {
  const int cx = cell_of(task.at(0)), cy = cell_of(task.at(1));
  double& c = competence_[static_cast<std::size_t>(cy) * o_.cells + cx];
  // The episode is played with the competence held before it; practice then raises it.
  const double ret = o_.max_return * c + o_.noise * standard_normal(rng_);
  const bool success = mastered(c);
  if (can_learn(cx, cy)) c = std::min(1.0, c + o_.gain);
  return {ret, success};
}

double SyntheticStudent::expected_return(const Task& task) const {
  const int cx = cell_of(task.at(0)), cy = cell_of(task.at(1));
  return o_.max_return * competence_[static_cast<std::size_t>(cy) * o_.cells + cx];
}

double SyntheticStudent::mastered_percent() const {
  const auto n =
      std::count_if(competence_.begin(), competence_.end(), [&](double c) { return mastered(c); });
  return 100.0 * static_cast<double>(n) / static_cast<double>(competence_.size());
}

double run_synthetic_curriculum(Teacher& teacher, int episodes, std::uint64_t seed,
                                const SyntheticStudentOptions& options) {
  SyntheticStudent student(options, seed);
  teacher.set_value_estimator([&student](const std::vector<std::vector<float>>& states) {
    std::vector<float> v;
    for (const auto& s : states) v.push_back(static_cast<float>(student.expected_return(s)));
    return v;
  });
  // The teacher's hooks in the order a student calls them: reset, steps, end of episode.
  const std::vector<float> no_action;
  for (int e = 0; e < episodes; ++e) {
    const Task task = teacher.sample_task();
    teacher.record_initial_state(task, task);
    const auto [ret, success] = student.play(task);
    teacher.step_update(task, no_action, ret, task, true);
    teacher.episodic_update(task, ret, success);
  }
  teacher.set_value_estimator(nullptr);  // the student is about to go
  return student.mastered_percent();
}

double welch_t(const std::vector<double>& a, const std::vector<double>& b) {
  // Means and unbiased variances of both samples.
  auto stats = [](const std::vector<double>& x) {
    double mean = 0, var = 0;
    for (double v : x) mean += v;
    mean /= static_cast<double>(x.size());
    for (double v : x) var += (v - mean) * (v - mean);
    return std::pair{mean, var / static_cast<double>(x.size() - 1)};
  };
  if (a.size() < 2 || b.size() < 2) throw UserError("welch_t: needs at least 2 values per side");
  const auto [ma, va] = stats(a);
  const auto [mb, vb] = stats(b);
  const double se =
      std::sqrt(va / static_cast<double>(a.size()) + vb / static_cast<double>(b.size()));
  return se > 0 ? (ma - mb) / se : 0.0;
}

}  // namespace cradle::teach

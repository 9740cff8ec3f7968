#include "train/loop.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace cradle::train {

std::string csv_cell(double value) {
  if (std::isnan(value)) return "";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", value);
  return buf;
}

std::string duration_text(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "--:--";
  const long s = static_cast<long>(seconds);
  char buf[32];
  std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", s / 3600, s / 60 % 60, s % 60);
  return buf;
}

void ProgressBar::show(long steps, double elapsed_seconds, const std::string& extra) const {
  if (!on_) return;
  const double done = static_cast<double>(steps) / total_;
  const double rate = (steps - first_) / std::max(elapsed_seconds, 1e-9);
  const int width = 30;
  const int filled = static_cast<int>(std::min(1.0, done) * width);
  std::fprintf(stderr, "\r[%s%s] %ld/%ld steps  %.0f steps/s  ETA %s  %s ",
               std::string(filled, '#').c_str(), std::string(width - filled, '.').c_str(), steps,
               total_, rate, duration_text((total_ - steps) / std::max(rate, 1e-9)).c_str(),
               extra.c_str());
  std::fflush(stderr);
}

void ProgressBar::finish() const {
  if (on_) std::fprintf(stderr, "\n");
}

long run_loop(learn::Learner& learner, const LoopOptions& options) {
  return run_loop([&learner]() -> learn::Learner& { return learner; }, options);
}

long run_loop(const std::function<learn::Learner&()>& current, const LoopOptions& options) {
  const long every = options.boundary_every;
  const bool exact = static_cast<bool>(options.next_boundary);
  auto offset = [&] { return options.offset ? options.offset() : 0L; };
  auto steps = [&] { return offset() + current().steps(); };
  auto next_boundary = [&] {
    if (exact) return options.next_boundary(steps());
    return every > 0 ? (steps() / every + 1) * every : -1L;
  };
  auto stopping = [&] { return options.stopping && options.stopping(); };
  long boundary = next_boundary();
  bool stop = false;  // a report said stop
  // One learn() call per interval between boundaries.
  while (steps() < options.total_steps && !stop && !stopping()) {
    const long before = steps();
    const long off = offset();
    const long target = exact ? std::min(boundary, options.total_steps) : options.total_steps;
    current().learn(target - off, [&](const learn::TrainStats& s) {
      if (options.report && !options.report(s)) {
        stop = true;
        return false;
      }
      return (exact || boundary < 0 || off + s.steps < boundary) && !stopping();
    });
    if (boundary >= 0 && steps() >= boundary && steps() < options.total_steps && !stop) {
      if (options.at_boundary) options.at_boundary();
      boundary = next_boundary();
    }
    if (steps() == before) break;  // a learner that cannot advance
  }
  return boundary;
}

}  // namespace cradle::train

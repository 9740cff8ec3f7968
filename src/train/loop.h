// The training loop of the one run (train::train, under `cradle train`, `cradle illustrate`,
// `cradle tma run`, `cradle sami train` and Python's): learn() in intervals that end at boundaries
// (checkpoints, evaluations, student resets: each learn() call starts fresh episodes, so a boundary
// is an episode boundary, as in a resumed run), a report after every update, and the progress bar
// and progress.csv cells the runs print.
#pragma once

#include <functional>
#include <memory>
#include <string>

#include "learn/learner.h"

namespace cradle::train {

// A progress.csv cell: %.6g, empty for NaN.
std::string csv_cell(double value);
// H:MM:SS, "--:--" when unknown.
std::string duration_text(double seconds);

// One line on stderr, redrawn: [####......] steps/total  rate steps/s  ETA H:MM:SS  <extra>.
class ProgressBar {
 public:
  // Counts the rate from `first` (the steps a resumed run starts at); draws nothing when off.
  ProgressBar(long total, long first, bool enabled) : total_(total), first_(first), on_(enabled) {}
  void show(long steps, double elapsed_seconds, const std::string& extra) const;
  void finish() const;  // ends the line

 private:
  long total_, first_;
  bool on_;
};

struct LoopOptions {
  long total_steps = 0;  // the run's env steps
  // Env steps between boundaries (0: none): learn() returns at the first report at or past each
  // multiple, at_boundary runs (unless the run is done) and a new learn() call continues.
  long boundary_every = 0;
  // Instead of boundary_every: the first boundary after the run's steps, each learn() call
  // training exactly to it (TeachMyAgent evaluates at exact step counts, whatever the learner's
  // report interval).
  std::function<long(long steps)> next_boundary;
  // The run's steps before its learner's first (a student reset starts a fresh learner's count at
  // 0 while the run's count goes on); null: 0. The run's steps are offset() + learner.steps().
  std::function<long()> offset;
  std::function<bool(const learn::TrainStats&)> report;  // after every update; false: stop
  std::function<void()> at_boundary;
  std::function<bool()> stopping;  // asked after every report and learn() call (Ctrl-C)
};

// Trains until the learner has total_steps, it cannot advance, a report says stop, or stopping()
// says so. Returns the boundary the run had not acted on when it ended (-1 without boundaries):
// the run ends past it when its last interval crossed it.
long run_loop(learn::Learner& learner, const LoopOptions& options);
// The same over a learner that a boundary may replace (a student reset): `learner` is asked for
// the current one before each learn() call.
long run_loop(const std::function<learn::Learner&()>& learner, const LoopOptions& options);

}  // namespace cradle::train

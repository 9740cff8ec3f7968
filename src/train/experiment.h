// What an experiment adds to the one run (train::train): evaluations of the learner at exact env
// step counts, files of its own in the run folder, and state that the run's checkpoints carry.
// The run does everything else (folder, vector, curriculum, learner, loop, checkpoints, resume,
// ranks); an experiment only measures and writes. TeachMyAgent's student run is one
// (train/tma_student.h: test-set evaluations, progress.csv of evaluations, test_returns.csv).
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "learn/learner.h"
#include "teach/controller.h"

namespace cradle::train {

// What an experiment's hooks see of the run at that moment.
struct RunView {
  learn::Learner& learner;     // the current learner (a fresh one after a reset)
  long steps = 0;              // the run's env steps (over every learner of a run that resets)
  long first_steps = 0;        // the run's env steps when this process began
  double seconds = 0;          // this process's time since it began training
  double teacher_seconds = 0;  // time spent in the teacher, this process
  teach::TeacherController* curriculum = nullptr;  // null for a run without a curriculum
};

class Experiment {
 public:
  virtual ~Experiment() = default;
  // Env steps between evaluations (>= 1): the run trains exactly to each multiple, evaluates,
  // then writes its checkpoint there (they replace --checkpoint-every). It also evaluates before
  // training starts and at its end.
  virtual long evaluate_every() const = 0;
  // The files it writes in the run folder, by relative path: removed by --overwrite, and a folder
  // holding any of them holds a run.
  virtual std::vector<std::string> files() const = 0;
  // Those it appends to: each checkpoint records their sizes, a resume cuts them back to it.
  virtual std::vector<std::string> logs() const = 0;
  // Before training (rank 0 only, as every hook): its files in `dir`, fresh, or continued from a
  // checkpoint whose state() was `resumed` (the logs already cut back to it).
  virtual void open(const std::filesystem::path& dir, const nlohmann::json* resumed) = 0;
  // Every progress report (the learner's losses and counters).
  virtual void report(const learn::TrainStats& /*stats*/) {}
  // Columns it adds to the run's logs/progress.csv (after the learner's), and their values at
  // each progress report, as many (what a resumed run's rows need is part of state()).
  virtual std::vector<std::string> progress_columns() const { return {}; }
  virtual std::vector<double> progress_values() const { return {}; }
  // Every training episode the teacher books.
  virtual void booked(const teach::EpisodeRecord& /*episode*/) {}
  // A fresh learner replaced the last one (TrainOptions::reset_every).
  virtual void learner_replaced() {}
  // One evaluation of run.learner; the run then dumps the teacher's state to its book and writes
  // its checkpoint.
  virtual void evaluate(const RunView& run) = 0;
  // What the next checkpoint records, for open() on resume.
  virtual nlohmann::json state() const = 0;
  // The progress bar's text.
  virtual std::string status() const { return ""; }
  // After the last checkpoint (stopped: ended early by a signal).
  virtual void finish(const RunView& /*run*/, bool /*stopped*/) {}
};

}  // namespace cradle::train

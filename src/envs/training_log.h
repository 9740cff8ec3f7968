// The training log: one JSON line per finished episode in <save_dir>/logs/training.jsonl (the
// reference's training.pkl entries, plus the episode score and wall time). Appended, never
// rewritten; flushed every `save_every` episodes and on close. Shared by every env of a run.
#pragma once

#include <chrono>
#include <filesystem>
#include <mutex>

#include "core/config.h"
#include "core/jsonl.h"
#include "envs/env.h"

namespace cradle::envs {

class TrainingLog {
 public:
  // append = false starts a new log (a new training run); true continues one (resume).
  TrainingLog(std::filesystem::path file, int save_every, bool append = false);
  ~TrainingLog();
  // Records one finished episode of `steps` env steps with its task's score (NaN: none).
  // Thread-safe.
  void record(const Info& info, int steps, double score);
  void flush();
  int episodes() const;
  const std::filesystem::path& file() const { return file_; }

 private:
  std::filesystem::path file_;
  int save_every_;
  mutable std::mutex mutex_;
  JsonlWriter writer_;
  int episodes_ = 0;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace cradle::envs

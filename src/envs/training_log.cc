#include "envs/training_log.h"

#include <cmath>

namespace cradle::envs {

TrainingLog::TrainingLog(std::filesystem::path file, int save_every, bool append)
    : file_(std::move(file)), save_every_(save_every), writer_(file_, append) {}

TrainingLog::~TrainingLog() {
  try {
    flush();
  } catch (...) {
    // A destructor must not throw; flush() reports failures to callers that ask.
  }
}

void TrainingLog::record(const Info& info, int steps, double score) {
  nlohmann::json entry = info.to_json();
  entry["steps"] = steps;
  if (!std::isnan(score)) entry["score"] = score;
  std::lock_guard lock(mutex_);
  entry["wall_time"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  writer_.write(entry);
  if (++episodes_ % save_every_ == 0) writer_.flush();
}

void TrainingLog::flush() {
  std::lock_guard lock(mutex_);
  writer_.flush();
}

int TrainingLog::episodes() const {
  std::lock_guard lock(mutex_);
  return episodes_;
}

}  // namespace cradle::envs

#include "envs/training_log.h"

#include <algorithm>
#include <cmath>

namespace cradle::envs {

TrainingLog::TrainingLog(std::filesystem::path file, int save_every, bool append, long episodes)
    : file_(std::move(file)),
      save_every_(save_every),
      writer_(std::in_place, file_, append),
      episodes_(append ? episodes : 0) {}

TrainingLog::TrainingLog(Relay relay) : save_every_(1), relay_(std::move(relay)) {}

TrainingLog::~TrainingLog() {
  try {
    flush();
  } catch (...) {
    // A destructor must not throw; flush() reports failures to callers that ask.
  }
}

void TrainingLog::record(const Info& info, int steps, double score, int slot) {
  nlohmann::json entry = info.to_json();
  entry["steps"] = steps;
  if (!std::isnan(score)) entry["score"] = score;
  if (relay_) {
    relay_(&entry);
    return;
  }
  add(std::move(entry), slot);
}

void TrainingLog::add(nlohmann::json entry, int slot) {
  std::lock_guard lock(mutex_);
  entry["wall_time"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  // Ordered mode: wait for commit() (slot order); otherwise written now.
  if (slot >= 0 && slot < static_cast<int>(pending_.size())) {
    pending_[slot].push_back(std::move(entry));
    return;
  }
  write_locked(entry);
}

void TrainingLog::write_locked(const nlohmann::json& entry) {
  writer_->write(entry);
  if (++episodes_ % save_every_ == 0) writer_->flush();
}

void TrainingLog::set_slots(int slots) {
  std::lock_guard lock(mutex_);
  pending_.resize(std::max(slots, 0));
}

void TrainingLog::commit() {
  std::lock_guard lock(mutex_);
  for (auto& entries : pending_) {
    for (const nlohmann::json& entry : entries) write_locked(entry);
    entries.clear();
  }
}

void TrainingLog::flush() {
  if (relay_) {
    relay_(nullptr);
    return;
  }
  commit();
  std::lock_guard lock(mutex_);
  writer_->flush();
}

long TrainingLog::episodes() const {
  std::lock_guard lock(mutex_);
  return episodes_;
}

}  // namespace cradle::envs

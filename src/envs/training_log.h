// The training log: one JSON line per finished episode in <save_dir>/logs/training.jsonl (the
// reference's training.pkl entries, plus the episode score and wall time). Appended, never
// rewritten; flushed every `save_every` episodes and on close. Shared by every env of a run.
#pragma once

#include <chrono>
#include <filesystem>
#include <functional>
#include <mutex>
#include <optional>
#include <vector>

#include "core/config.h"
#include "core/jsonl.h"
#include "envs/env.h"

namespace cradle::envs {

class TrainingLog {
 public:
  // append = false starts a new log (a new training run); true continues one (resume) that
  // already holds `episodes` entries.
  TrainingLog(std::filesystem::path file, int save_every, bool append = false, long episodes = 0);
  // A relay, for an env that runs in another process than the run's log (a process vector's
  // worker): record() hands each entry (without its wall time) to `relay`, and flush() hands it
  // null; nothing is written here. The run's log takes them with add() and flush().
  using Relay = std::function<void(const nlohmann::json* entry)>;
  explicit TrainingLog(Relay relay);
  ~TrainingLog();
  // Records one finished episode of `steps` env steps with its task's score (NaN: none).
  // Thread-safe. With slots (a vector's envs), env `slot`'s entries wait for commit(), which
  // writes them in slot order, so the file's line order does not depend on which env thread
  // finished first.
  void record(const Info& info, int steps, double score, int slot = -1);
  // Records an entry a relay recorded (record()'s, without the wall time, which is this log's).
  void add(nlohmann::json entry, int slot = -1);
  // Ordered mode for `slots` envs (called before any record).
  void set_slots(int slots);
  // Writes the waiting entries of every slot, in slot order (call from one thread between steps).
  void commit();
  // Commits, then hands the lines to the OS. UserError when the write fails.
  void flush();
  // Episodes written (committed) so far, counting those a continued log already held.
  long episodes() const;
  const std::filesystem::path& file() const { return file_; }

 private:
  std::filesystem::path file_;
  int save_every_;
  mutable std::mutex mutex_;
  std::optional<JsonlWriter> writer_;  // none in a relay
  Relay relay_;
  long episodes_ = 0;
  std::vector<std::vector<nlohmann::json>> pending_;  // per slot, waiting for commit()
  void write_locked(const nlohmann::json& entry);
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace cradle::envs

#include "envs/training_log.h"

#include <cmath>
#include <limits>

#include "envs/self_touch.h"

namespace cradle::envs {

double episode_score(Behavior behavior, const Info& info, int steps) {
  switch (behavior) {
    case Behavior::kSelfTouch:
      return static_cast<double>(info.right_hand_touches.size() + info.left_hand_touches.size()) /
             (2 * SelfTouch::kReferenceGeomsPerHand);
    case Behavior::kHandRegard: {
      if (steps == 0) return 0;
      const int sum =
          info.hand_regard[0] + info.hand_regard[1] + info.hand_regard[2] + info.hand_regard[3];
      return static_cast<double>(sum) / (4.0 * steps);
    }
    case Behavior::kNone:
      break;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

TrainingLog::TrainingLog(std::filesystem::path file, Behavior behavior, int save_every, bool append)
    : file_(std::move(file)),
      behavior_(behavior),
      save_every_(save_every),
      writer_(file_, append) {}

TrainingLog::~TrainingLog() {
  try {
    flush();
  } catch (...) {
    // A destructor must not throw; flush() reports failures to callers that ask.
  }
}

void TrainingLog::record(const Info& info, int steps) {
  nlohmann::json entry = info.to_json(behavior_);
  entry["steps"] = steps;
  const double score = episode_score(behavior_, info, steps);
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

// The BabyBench behaviours by name; "none" only counts steps.
#include <limits>

#include "core/error.h"
#include "envs/hand_regard.h"
#include "envs/self_touch.h"
#include "envs/task.h"

namespace cradle::envs {

double Task::score(const Info&, int) const { return std::numeric_limits<double>::quiet_NaN(); }

void Task::set_reset_options(const ResetOptions& options) {
  if (!options.empty()) {
    throw UserError("reset option '" + options.begin()->first + "' is not one this task takes");
  }
}

namespace {

class NoBehaviour final : public Task {
 public:
  void reset(const MimoCore&, Info&) override {}
  double after_step(const MimoCore&, Info&) override { return 0; }
};

}  // namespace

std::unique_ptr<Task> make_behaviour(const Config& config, const mjModel* m) {
  switch (config.behavior) {
    case Behavior::kSelfTouch:
      return std::make_unique<SelfTouch>(m);
    case Behavior::kHandRegard:
      return std::make_unique<HandRegard>(m, config.hand_regard_half_angle,
                                          config.hand_regard_occlusion);
    case Behavior::kNone:
      break;
  }
  return std::make_unique<NoBehaviour>();
}

}  // namespace cradle::envs

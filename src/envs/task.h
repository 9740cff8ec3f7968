// A task measures (and may reward) what the body does on the one MIMo env core (dm_control's
// split: the core is the physics and the senses, the task the rest). BabyBench behaviours only
// measure (reward 0); the sample tasks also set up each episode's start (a goal, start actions,
// a ball to catch) and move head and eyes between physics and observation. Every hook but reset
// and after_step has a default that does nothing.
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/config.h"
#include "core/rng.h"
#include "envs/env.h"
#include "envs/mimo_core.h"

namespace cradle::envs {

// What an evaluation shows of a task: eval/ draws it without knowing which task it is.
struct EvaluationPanels {
  // The video's right-column panels, up then down: a camera (side2, top), the eyes' red/cyan
  // anaglyph, or the skin map (MIMo's skin from above, hand contacts highlighted).
  enum class View { kSide2, kTop, kBinocular, kTouches };
  View up = View::kSide2, down = View::kTop;
  // The skin map's highlights: each hand's geoms (0 right, 1 left) and MIMo's geoms.
  std::array<std::vector<int>, 2> hand_geoms;
  std::vector<int> mimo_geoms;
  // Info keys holding geom lists (e.g. each hand's touches): a bar chart of the fraction of each
  // MIMo body's geoms they hold over the evaluation, and a training-log curve of their union
  // over episodes divided by `union_denominator`.
  struct GeomLists {
    std::vector<std::string> keys, labels;
    std::string title, union_label, file;  // file: the chart's PNG name
    double union_denominator = 1;
  };
  std::optional<GeomLists> geom_lists;
  // Values the task measures every step (Task::trace), saved with each trajectory under `key`
  // and drawn for the first evaluation episode, one line per label.
  struct Trace {
    std::string key, title, y_label, file;  // file: the plot's PNG name
    std::vector<std::string> labels;
    std::pair<double, double> y_range{0, 1};
    std::optional<std::pair<double, std::string>> threshold;  // a horizontal line and its label
  };
  std::optional<Trace> trace;
};

class Task {
 public:
  virtual ~Task() = default;
  // Once, when the env is built: the info keys the task writes.
  virtual void declare(Info& info) { (void)info; }
  // At the start of an episode, from the env's start state: draws the goal (goal_size values,
  // none for BabyBench) and sets up the episode's start on the body with the env's generator.
  virtual void initialize_episode(MimoCore& core, Rng& rng, std::span<double> goal) {
    (void)core, (void)rng, (void)goal;
  }
  // At the start of an episode, once the start state is set (the info is cleared).
  virtual void reset(const MimoCore& core, Info& info) = 0;
  // The action the physics gets (catch's jitter changes it).
  virtual std::span<const double> before_step(std::span<const double> action, Rng& rng) {
    (void)rng;
    return action;
  }
  // After the step's physics, before the senses read it (head and eyes follow a target).
  virtual void after_physics(MimoCore& core) { (void)core; }
  // The task's observation values: those appended to proprioception and the achieved goal.
  virtual void observe(const MimoCore& core, std::span<double> extra, std::span<double> achieved) {
    (void)core, (void)extra, (void)achieved;
  }
  // After each env step's observation; writes the info and returns the reward.
  virtual double after_step(const MimoCore& core, Info& info) = 0;
  // Options of the task's later episode starts (a curriculum's task parameters, e.g. reach's
  // ball offset); UserError for an option it does not take (by default: any).
  virtual void set_reset_options(const ResetOptions& options);
  // Score of an episode of `steps` env steps from its info (NaN: the task measures nothing).
  virtual double score(const Info& info, int steps) const;
  // What an evaluation of the task shows (default: two cameras, nothing else).
  virtual EvaluationPanels evaluation_panels() const { return {}; }
  // The per-step values of evaluation_panels().trace (as many as its labels) for the state `d`.
  virtual void trace(const mjData* d, std::span<double> values) const { (void)d, (void)values; }
};

// The BabyBench behaviour named by the config ("none" measures nothing).
std::unique_ptr<Task> make_behaviour(const Config& config, const mjModel* m);

}  // namespace cradle::envs

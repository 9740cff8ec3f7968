// The TeacherController (TeachMyAgent's teacher_controller): the one object a student talks to.
// It knows named task parameters, flat vectors and returns only, never an env: it maps teacher
// vectors to named parameters (three bounds formats), shuffles dimensions for the "rugged
// difficulty" criterion, scales rewards for the teacher, serves the test set and books everything
// it saw. Every method is thread-safe, so several envs of a vector may share one controller.
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "teach/teacher.h"

namespace cradle::teach {

// One named entry of a task space and the (min, max) of each of its dimensions.
struct ParamBounds {
  std::string name;
  std::vector<std::pair<float, float>> dims;
  bool scalar = true;  // format [min, max]: one value named `name`; else name_0, name_1, ...
};

// One entry in one of the three bounds formats: [min, max]; [min, max, n] (n dimensions sharing
// the bounds); [[min, max], ...] (one pair per dimension). UserError (naming the entry) otherwise.
ParamBounds parse_bounds(const std::string& name, const nlohmann::json& value);

// An ordered task space: the entries flattened in order into mins / maxs.
class TaskSpace {
 public:
  explicit TaskSpace(std::vector<ParamBounds> params);
  // From an ordered JSON object {name: bounds, ...} (the order is the dimensions' order).
  static TaskSpace from_json(const nlohmann::ordered_json& params);

  int dims() const { return static_cast<int>(mins_.size()); }
  const std::vector<float>& mins() const { return mins_; }
  const std::vector<float>& maxs() const { return maxs_; }
  const std::vector<ParamBounds>& params() const { return params_; }
  // One name per dimension: `name` for a scalar entry, name_<i> for the dimensions of the others.
  const std::vector<std::string>& dim_names() const { return dim_names_; }
  // {name: values} per entry, in order (a scalar entry has one value).
  std::vector<std::pair<std::string, std::vector<double>>> to_params(const Task& task) const;
  // The inverse of to_params: UserError for a missing or unknown name or a wrong count.
  Task from_params(const std::vector<std::pair<std::string, std::vector<double>>>& params) const;
  // {"names": [...], "mins": [...], "maxs": [...]}, one item per dimension.
  nlohmann::ordered_json bounds_json() const;

 private:
  std::vector<ParamBounds> params_;
  std::vector<float> mins_, maxs_;
  std::vector<std::string> dim_names_;
};

// Dimension shuffling: each dimension is cut into 4 equal intervals and the intervals are
// permuted (per dimension, by the run seed); a value inside interval k of the teacher's space maps
// linearly onto interval perm[k] of the real space.
class DimensionShuffle {
 public:
  static constexpr int kIntervals = 4;
  DimensionShuffle(std::vector<float> mins, std::vector<float> maxs, std::uint64_t seed);
  Task to_real(const Task& shuffled) const;
  Task to_shuffled(const Task& real) const;
  const std::vector<std::vector<int>>& permutations() const { return perm_; }

 private:
  float map(int dim, float value, bool forward) const;
  std::vector<float> mins_, maxs_;
  std::vector<std::vector<int>> perm_, inverse_;
};

// Return scaled from [lb, ub] onto [0, 1], clipped (TeachMyAgent's reward scaling).
double scale_return(double ret, double lb, double ub);

// The default test set: the int(sqrt(n)) x int(sqrt(n)) grid of linearly spaced values (endpoints
// included) when the space is exactly {stump_height, obstacle_spacing}; else n tasks drawn
// uniformly in the box by a private generator seeded 31 (the same set for every run).
std::vector<Task> default_test_set(const TaskSpace& space, int n);
// A test set from a CSV file whose header names the space's dimensions (in any order, extra
// columns refused): one task per row. UserError for a missing file, a bad header or cell.
std::vector<Task> read_test_set_csv(const std::filesystem::path& file, const TaskSpace& space);

struct ControllerOptions {
  std::uint64_t seed = 0;           // the run seed (dimension shuffling)
  bool shuffle_dimensions = false;  // the teacher works in the shuffled space
  bool scale_reward = false;        // the teacher sees returns scaled from [lb, ub] to [0, 1]
  double reward_lb = -100, reward_ub = 100;
  std::vector<Task> test_set;             // real-space tasks, used in order (wrapping around)
  long keep_periodical_task_samples = 0;  // steps between 100-task snapshots; 0: none
  int periodical_samples = 100;
};

// A training task as the env plays it (`real`) and as the teacher proposed it (`raw`).
struct SampledTask {
  Task raw, real;
};

// One finished training episode, as booked.
struct EpisodeRecord {
  long episode = 0;    // index among the run's training episodes
  long env_steps = 0;  // the controller's step count when it ended
  Task task;           // real space
  double ret = 0, norm_ret = 0;
  int length = 0;
  bool success = false;
};

// teacher.jsonl's lines: a booked training episode ("kind": "train"), and the teacher's dump at
// env_steps ("kind": "dump").
nlohmann::json train_line(const EpisodeRecord& e);
nlohmann::json dump_line(long env_steps, nlohmann::json teacher);

// A curriculum snapshot: `samples` non-exploratory tasks (real space) at env_steps.
struct PeriodicalRecord {
  long env_steps = 0;
  std::vector<Task> tasks;
};

class TeacherController {
 public:
  // The teacher works in the space's box (shuffled or not). UserError for a teacher of another
  // dimension, an empty or wrongly sized test set, or reward bounds with lb >= ub.
  TeacherController(std::unique_ptr<Teacher> teacher, TaskSpace space, ControllerOptions options);

  const TaskSpace& space() const { return space_; }
  // The next training task (booked in env_params_train).
  SampledTask sample_train_task();
  // Hooks of a training episode played on `raw` (the teacher's vector of sample_train_task).
  void record_initial_state(const Task& raw, const std::vector<float>& s0);
  void record_train_step(const std::vector<float>& s, const std::vector<float>& a, double r,
                         const std::vector<float>& s_next, bool done);
  void record_train_episode(const Task& raw, double ret, int length, bool success);
  // Resume: books an episode of an earlier run and replays it into the teacher (a sample is drawn
  // and discarded first so its state advances as it did), and sets the step count.
  void replay_train_episode(const Task& real, double ret, int length, bool success, long env_steps);
  void replay_periodical(PeriodicalRecord record);
  // Resume: the step count of the checkpoint the run continues from (the book's last episode may
  // have ended before it), so that later episodes and snapshots count on from there.
  void continue_from(long env_steps);

  // The test set in order; test_task walks through it and wraps around (books it).
  int test_set_size() const { return static_cast<int>(test_set_.size()); }
  const std::vector<Task>& test_set() const { return test_set_; }
  Task next_test_task();
  void record_test_episode(double ret, int length);

  long env_steps() const;
  long episodes() const;
  // What was booked since the last take (the run writes it to teacher.jsonl).
  std::vector<EpisodeRecord> take_episodes();
  std::vector<PeriodicalRecord> take_periodical();
  // The teacher's own dump (its name, bounds and records).
  nlohmann::json teacher_dump() const;
  // Everything booked, TeachMyAgent's names: env_params_train, env_train_rewards,
  // env_train_norm_rewards, env_train_len, env_params_test, env_test_rewards, env_test_len,
  // env_param_bounds, periodical_samples.
  nlohmann::json books() const;
  // Only the teacher's state (SPDL's value estimator, GMM snapshots) needs this.
  Teacher& teacher() { return *teacher_; }

 private:
  void maybe_snapshot();  // with mutex_ held

  mutable std::mutex mutex_;
  std::unique_ptr<Teacher> teacher_;
  TaskSpace space_;
  ControllerOptions options_;
  std::unique_ptr<DimensionShuffle> shuffle_;
  std::vector<Task> test_set_;
  int next_test_ = 0;
  long steps_ = 0, episodes_ = 0;
  // Books.
  std::vector<Task> params_train_, params_test_;
  std::vector<double> train_returns_, train_norm_returns_, test_returns_;
  std::vector<int> train_lengths_, test_lengths_;
  std::vector<PeriodicalRecord> periodical_;
  std::vector<EpisodeRecord> new_episodes_;
  std::size_t periodical_taken_ = 0;
};

}  // namespace cradle::teach

// TeacherController: bounds formats, dimension shuffling, reward scaling, test sets, books.
#include "teach/controller.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "core/error.h"

namespace cradle::teach {
namespace {

std::string text(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

// A finite number of a bounds entry, or a one-line error naming the entry.
float bound_value(const std::string& name, const nlohmann::json& v) {
  if (!v.is_number() || !std::isfinite(v.get<double>())) {
    throw UserError("task parameter '" + name + "': bound " + v.dump() +
                    " is not a finite number (expected [min, max], [min, max, n] or "
                    "[[min, max], ...])");
  }
  return v.get<float>();
}

std::pair<float, float> pair_of(const std::string& name, const nlohmann::json& v) {
  if (!v.is_array() || v.size() != 2) {
    throw UserError("task parameter '" + name + "': " + v.dump() + " is not a [min, max] pair");
  }
  const float lo = bound_value(name, v[0]), hi = bound_value(name, v[1]);
  if (lo > hi) {
    throw UserError("task parameter '" + name + "': min " + text(lo) + " > max " + text(hi) +
                    " (expected min <= max)");
  }
  return {lo, hi};
}

}  // namespace

ParamBounds parse_bounds(const std::string& name, const nlohmann::json& value) {
  const std::string expected = " (expected [min, max], [min, max, n] or [[min, max], ...])";
  if (!value.is_array() || value.empty()) {
    throw UserError("task parameter '" + name + "': bounds " + value.dump() + " are not a list" +
                    expected);
  }
  ParamBounds p{.name = name};
  // Format (c): a list of pairs, one per dimension.
  if (value[0].is_array()) {
    for (const nlohmann::json& item : value) p.dims.push_back(pair_of(name, item));
    p.scalar = false;
    return p;
  }
  // Format (a): [min, max], one dimension.
  if (value.size() == 2) {
    p.dims.push_back(pair_of(name, value));
    return p;
  }
  // Format (b): [min, max, n], n dimensions sharing the bounds.
  if (value.size() == 3) {
    const nlohmann::json& n = value[2];
    if (!n.is_number_integer() || n.get<long>() < 1) {
      throw UserError("task parameter '" + name + "': dimension count " + n.dump() +
                      " is not a positive integer" + expected);
    }
    const std::pair<float, float> b = pair_of(name, nlohmann::json{value[0], value[1]});
    p.dims.assign(n.get<std::size_t>(), b);
    p.scalar = false;
    return p;
  }
  throw UserError("task parameter '" + name + "': bounds " + value.dump() + " have " +
                  std::to_string(value.size()) + " items" + expected);
}

TaskSpace::TaskSpace(std::vector<ParamBounds> params) : params_(std::move(params)) {
  // Flatten in entry order; name each dimension as the test-set files do.
  if (params_.empty()) throw UserError("task space is empty (expected at least one parameter)");
  for (const ParamBounds& p : params_) {
    if (p.dims.empty()) throw UserError("task parameter '" + p.name + "' has no dimension");
    if (p.scalar && p.dims.size() != 1) {
      throw UserError("task parameter '" + p.name + "' is scalar but has several dimensions");
    }
    for (std::size_t k = 0; k < p.dims.size(); ++k) {
      mins_.push_back(p.dims[k].first);
      maxs_.push_back(p.dims[k].second);
      dim_names_.push_back(p.scalar ? p.name : p.name + "_" + std::to_string(k));
    }
  }
  for (std::size_t i = 0; i < dim_names_.size(); ++i) {
    if (std::count(dim_names_.begin(), dim_names_.end(), dim_names_[i]) > 1) {
      throw UserError("task space names dimension '" + dim_names_[i] + "' twice");
    }
  }
}

TaskSpace TaskSpace::from_json(const nlohmann::ordered_json& params) {
  if (!params.is_object()) {
    throw UserError("task space " + params.dump() + " is not a mapping {name: bounds}");
  }
  std::vector<ParamBounds> list;
  for (const auto& [name, value] : params.items()) {
    list.push_back(parse_bounds(name, nlohmann::json::parse(value.dump())));
  }
  return TaskSpace(std::move(list));
}

std::vector<std::pair<std::string, std::vector<double>>> TaskSpace::to_params(
    const Task& task) const {
  if (task.size() != mins_.size()) {
    throw UserError("task has " + std::to_string(task.size()) + " values; expected " +
                    std::to_string(mins_.size()));
  }
  std::vector<std::pair<std::string, std::vector<double>>> out;
  std::size_t i = 0;
  for (const ParamBounds& p : params_) {
    std::vector<double> values(task.begin() + i, task.begin() + i + p.dims.size());
    i += p.dims.size();
    out.emplace_back(p.name, std::move(values));
  }
  return out;
}

Task TaskSpace::from_params(
    const std::vector<std::pair<std::string, std::vector<double>>>& params) const {
  Task task;
  for (const ParamBounds& p : params_) {
    const auto it = std::find_if(params.begin(), params.end(),
                                 [&](const auto& item) { return item.first == p.name; });
    if (it == params.end()) throw UserError("task parameter '" + p.name + "' is missing");
    if (it->second.size() != p.dims.size()) {
      throw UserError("task parameter '" + p.name + "' has " + std::to_string(it->second.size()) +
                      " values; expected " + std::to_string(p.dims.size()));
    }
    for (double v : it->second) task.push_back(static_cast<float>(v));
  }
  if (params.size() != params_.size()) {
    throw UserError("task has " + std::to_string(params.size()) + " parameters; expected " +
                    std::to_string(params_.size()));
  }
  return task;
}

nlohmann::ordered_json TaskSpace::bounds_json() const {
  nlohmann::ordered_json out;
  out["names"] = dim_names_;
  out["mins"] = mins_;
  out["maxs"] = maxs_;
  return out;
}

DimensionShuffle::DimensionShuffle(std::vector<float> mins, std::vector<float> maxs,
                                   std::uint64_t seed)
    : mins_(std::move(mins)), maxs_(std::move(maxs)) {
  // One Fisher-Yates permutation of the 4 intervals per dimension, from the run seed.
  Rng rng(seed);
  for (std::size_t d = 0; d < mins_.size(); ++d) {
    std::vector<int> perm(kIntervals), inverse(kIntervals);
    for (int k = 0; k < kIntervals; ++k) perm[k] = k;
    for (int k = kIntervals - 1; k > 0; --k) {
      const int j = static_cast<int>(rng.next() % static_cast<std::uint64_t>(k + 1));
      std::swap(perm[k], perm[j]);
    }
    for (int k = 0; k < kIntervals; ++k) inverse[perm[k]] = k;
    perm_.push_back(perm);
    inverse_.push_back(inverse);
  }
}

float DimensionShuffle::map(int dim, float value, bool forward) const {
  const double lo = mins_[dim], width = (static_cast<double>(maxs_[dim]) - lo) / kIntervals;
  if (width <= 0) return value;
  // Interval k and the position inside it; the top edge belongs to the last interval.
  const double u = (value - lo) / width;
  const int k = std::clamp(static_cast<int>(std::floor(u)), 0, kIntervals - 1);
  const double frac = u - k;
  const int to = forward ? perm_[dim][k] : inverse_[dim][k];
  return static_cast<float>(lo + (to + frac) * width);
}

Task DimensionShuffle::to_real(const Task& shuffled) const {
  Task out(shuffled.size());
  for (std::size_t d = 0; d < shuffled.size(); ++d)
    out[d] = map(static_cast<int>(d), shuffled[d], true);
  return out;
}

Task DimensionShuffle::to_shuffled(const Task& real) const {
  Task out(real.size());
  for (std::size_t d = 0; d < real.size(); ++d) out[d] = map(static_cast<int>(d), real[d], false);
  return out;
}

double scale_return(double ret, double lb, double ub) {
  return std::clamp((ret - lb) / (ub - lb), 0.0, 1.0);
}

std::vector<Task> default_test_set(const TaskSpace& space, int n) {
  if (n < 1) throw UserError("test set size " + std::to_string(n) + " (expected at least 1)");
  const std::vector<std::string>& names = space.dim_names();
  const std::vector<float>& lo = space.mins();
  const std::vector<float>& hi = space.maxs();
  std::vector<Task> out;
  // Stump Tracks' 2-D space: the grid, first dimension outer.
  const bool stumps = names.size() == 2 &&
                      std::count(names.begin(), names.end(), "stump_height") == 1 &&
                      std::count(names.begin(), names.end(), "obstacle_spacing") == 1;
  if (stumps) {
    const int side = static_cast<int>(std::sqrt(static_cast<double>(n)));
    auto at = [&](int d, int i) {
      return side == 1 ? lo[d] : static_cast<float>(lo[d] + (hi[d] - lo[d]) * i / (side - 1.0));
    };
    for (int i = 0; i < side; ++i)
      for (int j = 0; j < side; ++j) out.push_back({at(0, i), at(1, j)});
    return out;
  }
  // Any other space: uniform draws of a fixed generator.
  Rng rng(31);
  for (int i = 0; i < n; ++i) {
    Task t(lo.size());
    for (std::size_t d = 0; d < t.size(); ++d)
      t[d] = std::min(hi[d], static_cast<float>(rng.uniform(lo[d], hi[d])));
    out.push_back(std::move(t));
  }
  return out;
}

std::vector<Task> read_test_set_csv(const std::filesystem::path& file, const TaskSpace& space) {
  std::ifstream in(file);
  if (!in) throw UserError("test set '" + file.string() + "' cannot be read");
  auto split = [](const std::string& line) {
    std::vector<std::string> cells;
    std::stringstream s(line);
    std::string cell;
    while (std::getline(s, cell, ',')) cells.push_back(cell);
    return cells;
  };
  std::string line;
  std::getline(in, line);
  const std::vector<std::string> header = split(line);
  // Column of each of the space's dimensions.
  std::vector<int> column;
  for (const std::string& name : space.dim_names()) {
    const auto it = std::find(header.begin(), header.end(), name);
    if (it == header.end()) {
      throw UserError("test set '" + file.string() + "' has no column '" + name +
                      "' (its columns: " + line + ")");
    }
    column.push_back(static_cast<int>(it - header.begin()));
  }
  if (header.size() != column.size()) {
    throw UserError("test set '" + file.string() + "' has columns " + line +
                    "; expected exactly the task space's dimensions");
  }
  std::vector<Task> out;
  int row = 1;
  while (std::getline(in, line)) {
    ++row;
    if (line.empty()) continue;
    const std::vector<std::string> cells = split(line);
    if (cells.size() != header.size()) {
      throw UserError("test set '" + file.string() + "' line " + std::to_string(row) + " has " +
                      std::to_string(cells.size()) + " cells; expected " +
                      std::to_string(header.size()));
    }
    Task t;
    for (int c : column) {
      try {
        std::size_t used = 0;
        t.push_back(std::stof(cells[c], &used));
        if (used != cells[c].size()) throw std::invalid_argument(cells[c]);
      } catch (const std::exception&) {
        throw UserError("test set '" + file.string() + "' line " + std::to_string(row) + ": '" +
                        cells[c] + "' is not a number");
      }
    }
    out.push_back(std::move(t));
  }
  if (out.empty()) throw UserError("test set '" + file.string() + "' has no task");
  return out;
}

TeacherController::TeacherController(std::unique_ptr<Teacher> teacher, TaskSpace space,
                                     ControllerOptions options)
    : teacher_(std::move(teacher)), space_(std::move(space)), options_(std::move(options)) {
  // The teacher proposes vectors of the space's box; the test set must be of its dimension.
  if (!teacher_) throw UserError("teacher controller: no teacher");
  if (teacher_->dims() != space_.dims()) {
    throw UserError("teacher works in " + std::to_string(teacher_->dims()) +
                    " dimensions; the task space has " + std::to_string(space_.dims()));
  }
  if (!(options_.reward_lb < options_.reward_ub)) {
    throw UserError("reward bounds [" + text(options_.reward_lb) + ", " + text(options_.reward_ub) +
                    "]: expected lb < ub");
  }
  if (options_.keep_periodical_task_samples < 0) {
    throw UserError("keep_periodical_task_samples " +
                    std::to_string(options_.keep_periodical_task_samples) +
                    " (expected 0 for none or a positive step count)");
  }
  test_set_ = std::move(options_.test_set);
  if (test_set_.empty()) throw UserError("teacher controller: the test set is empty");
  for (const Task& t : test_set_) {
    if (static_cast<int>(t.size()) != space_.dims()) {
      throw UserError("test task of " + std::to_string(t.size()) + " values; expected " +
                      std::to_string(space_.dims()));
    }
  }
  if (options_.shuffle_dimensions) {
    shuffle_ = std::make_unique<DimensionShuffle>(space_.mins(), space_.maxs(), options_.seed);
  }
}

SampledTask TeacherController::sample_train_task() {
  std::lock_guard lock(mutex_);
  SampledTask t;
  t.raw = teacher_->sample_task();
  t.real = shuffle_ ? shuffle_->to_real(t.raw) : t.raw;
  params_train_.push_back(t.real);
  return t;
}

void TeacherController::record_initial_state(const Task& raw, const std::vector<float>& s0) {
  std::lock_guard lock(mutex_);
  teacher_->record_initial_state(raw, s0);
}

void TeacherController::record_train_step(const std::vector<float>& s, const std::vector<float>& a,
                                          double r, const std::vector<float>& s_next, bool done) {
  std::lock_guard lock(mutex_);
  ++steps_;
  teacher_->step_update(s, a, r, s_next, done);
  maybe_snapshot();
}

void TeacherController::maybe_snapshot() {
  // Every keep_periodical_task_samples steps: the curriculum without exploration noise.
  const long every = options_.keep_periodical_task_samples;
  if (every <= 0 || steps_ % every != 0) return;
  if (!teacher_->is_non_exploratory_task_sampling_available()) return;
  PeriodicalRecord record{.env_steps = steps_};
  for (int i = 0; i < options_.periodical_samples; ++i) {
    const Task raw = teacher_->non_exploratory_task_sampling();
    record.tasks.push_back(shuffle_ ? shuffle_->to_real(raw) : raw);
  }
  periodical_.push_back(std::move(record));
}

void TeacherController::record_train_episode(const Task& raw, double ret, int length,
                                             bool success) {
  std::lock_guard lock(mutex_);
  // The teacher sees the raw vector and, with scaling on, the scaled return.
  const double norm = scale_return(ret, options_.reward_lb, options_.reward_ub);
  teacher_->episodic_update(raw, options_.scale_reward ? norm : ret, success);
  const Task real = shuffle_ ? shuffle_->to_real(raw) : raw;
  train_returns_.push_back(ret);
  train_norm_returns_.push_back(norm);
  train_lengths_.push_back(length);
  new_episodes_.push_back({.episode = episodes_++,
                           .env_steps = steps_,
                           .task = real,
                           .ret = ret,
                           .norm_ret = norm,
                           .length = length,
                           .success = success});
}

void TeacherController::replay_train_episode(const Task& real, double ret, int length, bool success,
                                             long env_steps) {
  std::lock_guard lock(mutex_);
  if (static_cast<int>(real.size()) != space_.dims()) {
    throw UserError("booked task of " + std::to_string(real.size()) + " values; expected " +
                    std::to_string(space_.dims()));
  }
  (void)teacher_->sample_task();
  const Task raw = shuffle_ ? shuffle_->to_shuffled(real) : real;
  const double norm = scale_return(ret, options_.reward_lb, options_.reward_ub);
  teacher_->episodic_update(raw, options_.scale_reward ? norm : ret, success);
  params_train_.push_back(real);
  train_returns_.push_back(ret);
  train_norm_returns_.push_back(norm);
  train_lengths_.push_back(length);
  ++episodes_;
  steps_ = std::max(steps_, env_steps);
}

void TeacherController::replay_periodical(PeriodicalRecord record) {
  std::lock_guard lock(mutex_);
  steps_ = std::max(steps_, record.env_steps);
  periodical_.push_back(std::move(record));
  periodical_taken_ = periodical_.size();
}

void TeacherController::continue_from(long env_steps) {
  std::lock_guard lock(mutex_);
  steps_ = std::max(steps_, env_steps);
}

Task TeacherController::next_test_task() {
  std::lock_guard lock(mutex_);
  const Task t = test_set_[next_test_];
  next_test_ = (next_test_ + 1) % static_cast<int>(test_set_.size());
  params_test_.push_back(t);
  return t;
}

void TeacherController::record_test_episode(double ret, int length) {
  std::lock_guard lock(mutex_);
  test_returns_.push_back(ret);
  test_lengths_.push_back(length);
}

long TeacherController::env_steps() const {
  std::lock_guard lock(mutex_);
  return steps_;
}

long TeacherController::episodes() const {
  std::lock_guard lock(mutex_);
  return episodes_;
}

nlohmann::json train_line(const EpisodeRecord& e) {
  return {{"kind", "train"}, {"episode", e.episode}, {"env_steps", e.env_steps}, {"task", e.task},
          {"return", e.ret}, {"length", e.length},   {"success", e.success}};
}

nlohmann::json dump_line(long env_steps, nlohmann::json teacher) {
  return {{"kind", "dump"}, {"env_steps", env_steps}, {"teacher", std::move(teacher)}};
}

std::vector<EpisodeRecord> TeacherController::take_episodes() {
  std::lock_guard lock(mutex_);
  return std::exchange(new_episodes_, {});
}

std::vector<PeriodicalRecord> TeacherController::take_periodical() {
  std::lock_guard lock(mutex_);
  std::vector<PeriodicalRecord> out(periodical_.begin() + periodical_taken_, periodical_.end());
  periodical_taken_ = periodical_.size();
  return out;
}

nlohmann::json TeacherController::teacher_dump() const {
  std::lock_guard lock(mutex_);
  return teacher_->dump();
}

nlohmann::json TeacherController::books() const {
  std::lock_guard lock(mutex_);
  nlohmann::json periodical = nlohmann::json::array();
  for (const PeriodicalRecord& p : periodical_)
    periodical.push_back({{"env_steps", p.env_steps}, {"tasks", p.tasks}});
  nlohmann::json bounds = nlohmann::json::array();
  for (const ParamBounds& p : space_.params()) {
    nlohmann::json dims = nlohmann::json::array();
    for (const auto& [lo, hi] : p.dims) dims.push_back({lo, hi});
    bounds.push_back({p.name, p.scalar ? dims[0] : dims});
  }
  return {{"env_params_train", params_train_},
          {"env_train_rewards", train_returns_},
          {"env_train_norm_rewards", train_norm_returns_},
          {"env_train_len", train_lengths_},
          {"env_params_test", params_test_},
          {"env_test_rewards", test_returns_},
          {"env_test_len", test_lengths_},
          {"env_param_bounds", bounds},
          {"periodical_samples", periodical}};
}

}  // namespace cradle::teach

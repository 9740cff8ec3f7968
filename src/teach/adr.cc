// ADR: samples in a current box, often pinning one coordinate to a free bound; a full queue of
// returns at a bound pushes it outward (mean >= max threshold) or inward (mean <= min threshold).
#include <algorithm>
#include <deque>
#include <numeric>
#include <string>

#include "core/error.h"
#include "teach/teacher.h"

namespace cradle::teach {
namespace {

class AdrTeacher final : public Teacher {
 public:
  AdrTeacher(std::vector<float> mins, std::vector<float> maxs, std::uint64_t seed, AdrParams p)
      : Teacher(std::move(mins), std::move(maxs), seed), p_(std::move(p)) {
    // Check the parameters before anything depends on them.
    if (!(p_.step_size > 0.f)) throw UserError("adr: step_size must be > 0");
    if (p_.queue_len < 1) throw UserError("adr: queue_len must be >= 1");
    if (!(p_.boundary_prob >= 0.0 && p_.boundary_prob <= 1.0))
      throw UserError("adr: boundary_prob must lie in [0, 1]");
    if (!(p_.min_reward_thr < p_.max_reward_thr))
      throw UserError("adr: min_reward_thr must be below max_reward_thr");
    // The box starts as a single point: the given one, or a uniform draw.
    if (p_.initial_point.empty()) {
      cur_min_ = uniform_task();
    } else {
      if (static_cast<int>(p_.initial_point.size()) != dims())
        throw UserError("adr: initial_point has " + std::to_string(p_.initial_point.size()) +
                        " values; expected " + std::to_string(dims()));
      for (int i = 0; i < dims(); ++i)
        if (p_.initial_point[i] < mins_[i] || p_.initial_point[i] > maxs_[i])
          throw UserError("adr: initial_point[" + std::to_string(i) + "] is outside the bounds");
      cur_min_ = p_.initial_point;
    }
    cur_max_ = cur_min_;
    min_q_.resize(dims());
    max_q_.resize(dims());
  }

  Task sample_task() override {
    // Uniform in the current box.
    Task x(dims());
    for (int i = 0; i < dims(); ++i)
      x[i] = static_cast<float>(rng_.uniform(cur_min_[i], cur_max_[i]));
    clip_current(x);
    // Sometimes pin one dimension to a bound that can still move outward.
    if (rng_.uniform() < p_.boundary_prob) {
      const int i = std::min(dims() - 1, static_cast<int>(rng_.uniform() * dims()));
      const bool min_free = cur_min_[i] != mins_[i], max_free = cur_max_[i] != maxs_[i];
      if (min_free && max_free) {
        x[i] = rng_.uniform() < 0.5 ? cur_min_[i] : cur_max_[i];
      } else if (min_free) {
        x[i] = cur_min_[i];
      } else if (max_free) {
        x[i] = cur_max_[i];
      }
    }
    return x;
  }

  void episodic_update(const Task& task, double ret, bool) override {
    check_episode(task, ret);
    ++episode_;
    for (int i = 0; i < dims(); ++i) {
      // Min side: expand down to the global min, shrink up to the current max.
      if (task[i] == cur_min_[i]) {
        min_q_[i].push_back(ret);
        if (static_cast<int>(min_q_[i].size()) >= p_.queue_len) {
          const double mean = mean_of(min_q_[i]);
          if (mean >= p_.max_reward_thr) {
            move(cur_min_[i], std::max(cur_min_[i] - p_.step_size, mins_[i]), i, "min");
          } else if (mean <= p_.min_reward_thr) {
            move(cur_min_[i], std::min(cur_min_[i] + p_.step_size, cur_max_[i]), i, "min");
          }
          min_q_[i].clear();
        }
      }
      // Max side, symmetric (a single-point box feeds both queues).
      if (task[i] == cur_max_[i]) {
        max_q_[i].push_back(ret);
        if (static_cast<int>(max_q_[i].size()) >= p_.queue_len) {
          const double mean = mean_of(max_q_[i]);
          if (mean >= p_.max_reward_thr) {
            move(cur_max_[i], std::min(cur_max_[i] + p_.step_size, maxs_[i]), i, "max");
          } else if (mean <= p_.min_reward_thr) {
            move(cur_max_[i], std::max(cur_max_[i] - p_.step_size, cur_min_[i]), i, "max");
          }
          max_q_[i].clear();
        }
      }
    }
  }

  nlohmann::json dump() const override {
    nlohmann::json j = Teacher::dump();
    j["cur_min"] = cur_min_;
    j["cur_max"] = cur_max_;
    j["bound_changes"] = changes_;
    return j;
  }
  const char* name() const override { return "adr"; }

 private:
  static double mean_of(const std::deque<double>& q) {
    return std::accumulate(q.begin(), q.end(), 0.0) / static_cast<double>(q.size());
  }
  // Float rounding of the current box must not leave it.
  void clip_current(Task& x) const {
    for (int i = 0; i < dims(); ++i) x[i] = std::clamp(x[i], cur_min_[i], cur_max_[i]);
  }
  // Applies a bound change and logs it with its episode index.
  void move(float& bound, float value, int dim, const char* side) {
    if (value == bound) return;
    bound = value;
    changes_.push_back({{"episode", episode_}, {"dim", dim}, {"side", side}, {"value", value}});
  }

  AdrParams p_;
  Task cur_min_, cur_max_;
  std::vector<std::deque<double>> min_q_, max_q_;
  long episode_ = 0;
  nlohmann::json changes_ = nlohmann::json::array();
};

}  // namespace

std::unique_ptr<Teacher> make_adr_teacher(std::vector<float> mins, std::vector<float> maxs,
                                          std::uint64_t seed, AdrParams params) {
  return std::make_unique<AdrTeacher>(std::move(mins), std::move(maxs), seed, std::move(params));
}

}  // namespace cradle::teach

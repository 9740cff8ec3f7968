// The GMM teachers' shared checks and sampling policy.
#include "teach/gmm_teacher.h"

#include <algorithm>
#include <string>
#include <utility>

#include "core/error.h"

namespace cradle::teach {

GmmTeacher::GmmTeacher(std::vector<float> mins, std::vector<float> maxs, std::uint64_t seed,
                       const std::string& who, GmmTeacherParams params)
    : Teacher(std::move(mins), std::move(maxs), seed), p_(std::move(params)), fit_rng_(seed + 1) {
  // Check the parameters before anything depends on them.
  if (p_.fit_rate < 2) throw UserError(who + ": fit_rate must be >= 2");
  if (p_.potential_ks.empty()) throw UserError(who + ": potential_ks is empty");
  for (int k : p_.potential_ks)
    if (k < 1 || k > p_.fit_rate)
      throw UserError(who + ": potential k " + std::to_string(k) + "; expected 1..fit_rate");
  if (!(p_.random_task_ratio >= 0 && p_.random_task_ratio <= 1))
    throw UserError(who + ": random_task_ratio must lie in [0, 1]");
  if (p_.initial_dist) check_dist(*p_.initial_dist, who + ": initial_dist");
}

Task GmmTeacher::sample_task() {
  // Bootstrap under high expert knowledge: the env's easy region (origin -2).
  if (!fitted_ && p_.initial_dist) {
    last_origin_ = -2;
    return gaussian_task(*p_.initial_dist);
  }
  // Bootstrap, before the first fit, and a random_task_ratio share: uniform (origin -1).
  if (!fitted_ || rng_.uniform() < p_.random_task_ratio) {
    last_origin_ = -1;
    return uniform_task();
  }
  return from_component(pick_component());
}

Task GmmTeacher::non_exploratory_task_sampling() {
  if (!fitted_) return uniform_task();
  return from_component(pick_component());
}

nlohmann::json GmmTeacher::dump() const {
  nlohmann::json j = Teacher::dump();
  j["episodes"] = origins_.size();
  j["fits"] = fits_;
  j["failed_fits"] = failed_fits_;
  j["task_origins"] = origins_;
  return j;
}

bool GmmTeacher::record_episode() {
  origins_.push_back(last_origin_);
  return origins_.size() % static_cast<std::size_t>(p_.fit_rate) == 0;
}

bool GmmTeacher::refit(const Eigen::MatrixXd& x, const std::string& criterion) {
  Gmm g = fit_best_gmm(x, p_.potential_ks, criterion, fit_rng_);
  ++fits_;
  // No usable mixture (degenerate data): keep sampling from the previous one, or uniformly
  // before the first, rather than from a mixture that would give NaN tasks.
  if (!usable(g)) {
    ++failed_fits_;
    return false;
  }
  gmm_ = std::move(g);
  fitted_ = true;
  return true;
}

int GmmTeacher::pick_component() {
  double total = 0;
  for (int c = 0; c < gmm_.k(); ++c) total += progress(c);
  if (total <= 0) return std::min(gmm_.k() - 1, static_cast<int>(rng_.uniform() * gmm_.k()));
  double u = rng_.uniform() * total;
  for (int c = 0; c < gmm_.k(); ++c) {
    u -= progress(c);
    if (u < 0) return c;
  }
  return gmm_.k() - 1;
}

Task GmmTeacher::from_component(int c) {
  last_origin_ = c;
  const Eigen::VectorXd s = sample_component(gmm_, c, rng_);
  Task task(dims());
  for (int i = 0; i < dims(); ++i) task[i] = static_cast<float>(s[i]);
  clip(task);
  return task;
}

}  // namespace cradle::teach

// RIAC: every region of a binary tree keeps a FIFO of (task, return); a full leaf is cut where the
// absolute learning progress (ALP) of the two halves differs most; regions are sampled by ALP.
#include <algorithm>
#include <cmath>
#include <deque>
#include <numbers>
#include <string>
#include <utility>

#include "core/error.h"
#include "teach/teacher.h"

namespace cradle::teach {
namespace {

struct Pair {
  Task task;
  double ret;
};

struct Region {
  Task lo, hi;
  std::deque<Pair> pairs;
  double alp = 0;
  int child[2] = {-1, -1};
  bool leaf() const { return child[0] < 0; }
  bool contains(const Task& t) const {
    for (std::size_t i = 0; i < t.size(); ++i)
      if (t[i] < lo[i] || t[i] > hi[i]) return false;
    return true;
  }
};

class RiacTeacher final : public Teacher {
 public:
  RiacTeacher(std::vector<float> mins, std::vector<float> maxs, std::uint64_t seed, RiacParams p)
      : Teacher(std::move(mins), std::move(maxs), seed), p_(p) {
    // Resolve the derived defaults, then check everything.
    if (p_.max_region_size < 2) throw UserError("riac: max_region_size must be >= 2");
    if (p_.alp_window == 0) p_.alp_window = p_.max_region_size;
    if (p_.min_region_size == 0) p_.min_region_size = p_.max_region_size / 20.0;
    if (p_.alp_window < 2) throw UserError("riac: alp_window must be >= 2");
    if (p_.nb_split_attempts < 1) throw UserError("riac: nb_split_attempts must be >= 1");
    if (!(p_.min_region_size > 0 && p_.min_region_size <= p_.max_region_size))
      throw UserError("riac: min_region_size must lie in (0, max_region_size]");
    if (!(p_.min_dims_range_ratio >= 0 && p_.min_dims_range_ratio < 0.5))
      throw UserError("riac: min_dims_range_ratio must lie in [0, 0.5)");
    if (!(p_.discard_ratio >= 0 && p_.discard_ratio <= 1))
      throw UserError("riac: discard_ratio must lie in [0, 1]");
    regions_.push_back({mins_, maxs_, {}, 0, {-1, -1}});
  }

  Task sample_task() override {
    const double u = rng_.uniform();
    // 20 %, and the very first draw: uniform in the whole space.
    if (u >= 0.7 && u < 0.9) return uniform_task();
    const Region& r = regions_[pick_region()];
    if (u < 0.7 || r.pairs.empty()) {
      // 70 %: uniform inside a region chosen by ALP.
      Task x(dims());
      for (int i = 0; i < dims(); ++i) x[i] = static_cast<float>(rng_.uniform(r.lo[i], r.hi[i]));
      clip(x);
      return x;
    }
    // 10 %: the region's lowest-return task plus N(0, 0.1), kept inside the slightly shrunk region.
    const Pair& worst = *std::min_element(
        r.pairs.begin(), r.pairs.end(), [](const Pair& a, const Pair& b) { return a.ret < b.ret; });
    Task x = worst.task;
    for (int i = 0; i < dims(); ++i)
      x[i] = std::clamp(static_cast<float>(x[i] + 0.1 * gaussian()), r.lo[i] + 1e-5f,
                        std::max(r.lo[i] + 1e-5f, r.hi[i] - 1e-5f));
    return x;
  }

  void episodic_update(const Task& task, double ret, bool) override {
    check_episode(task, ret);
    // Walk down the matching path, adding the pair to every node on it.
    int node = 0;
    while (node >= 0) {
      Region& r = regions_[node];
      r.pairs.push_back({task, ret});
      if (static_cast<int>(r.pairs.size()) > p_.max_region_size + 1) r.pairs.pop_front();
      r.alp = alp_of(r.pairs);
      if (r.leaf()) {
        if (static_cast<int>(r.pairs.size()) > p_.max_region_size) split(node);
        break;
      }
      const int next = regions_[r.child[0]].contains(task) ? r.child[0] : r.child[1];
      node = regions_[next].contains(task) ? next : -1;
    }
  }

  nlohmann::json dump() const override {
    nlohmann::json j = Teacher::dump();
    nlohmann::json regions = nlohmann::json::array();
    for (const Region& r : regions_)
      regions.push_back({{"lo", r.lo},
                         {"hi", r.hi},
                         {"alp", r.alp},
                         {"size", r.pairs.size()},
                         {"leaf", r.leaf()}});
    j["regions"] = std::move(regions);
    j["max_region_size"] = p_.max_region_size;
    return j;
  }
  const char* name() const override { return "riac"; }

 private:
  // |mean(older half) - mean(newer half)| over the last alp_window returns.
  double alp_of(const std::deque<Pair>& pairs) const {
    const int n = static_cast<int>(pairs.size());
    if (n <= 2) return 0;
    const int w = std::min(n, p_.alp_window), h = w / 2;
    double older = 0, newer = 0;
    for (int k = n - w; k < n - h; ++k) older += pairs[k].ret;
    for (int k = n - h; k < n; ++k) newer += pairs[k].ret;
    return std::abs(older / (w - h) - newer / h);
  }

  // Region index with probability proportional to ALP (uniform when every ALP is 0).
  int pick_region() {
    double total = 0;
    for (const Region& r : regions_) total += r.alp;
    const int count = static_cast<int>(regions_.size());
    if (total <= 0) return std::min(count - 1, static_cast<int>(rng_.uniform() * count));
    double u = rng_.uniform() * total;
    for (int k = 0; k < count; ++k) {
      u -= regions_[k].alp;
      if (u < 0) return k;
    }
    return count - 1;
  }

  // Standard normal (Box-Muller).
  double gaussian() {
    const double u1 = 1.0 - rng_.uniform(), u2 = rng_.uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
  }

  // Cuts a full leaf in two at the best valid candidate, or forgets its oldest pairs.
  void split(int node) {
    const Region parent = regions_[node];
    double best_score = -1;
    Region best[2];
    for (int attempt = 0; attempt < p_.nb_split_attempts; ++attempt) {
      // Redraw the cut (bounded) until both halves hold at least minlen pairs.
      Region half[2];
      bool filled = false;
      for (int redraw = 0; redraw < 100 && !filled; ++redraw) {
        const int dim = std::min(dims() - 1, static_cast<int>(rng_.uniform() * dims()));
        const float cut = static_cast<float>(rng_.uniform(parent.lo[dim], parent.hi[dim]));
        half[0] = {parent.lo, parent.hi, {}, 0, {-1, -1}};
        half[1] = half[0];
        half[0].hi[dim] = cut;
        half[1].lo[dim] = cut;
        for (const Pair& q : parent.pairs) half[q.task[dim] <= cut ? 0 : 1].pairs.push_back(q);
        filled = half[0].pairs.size() >= p_.min_region_size &&
                 half[1].pairs.size() >= p_.min_region_size;
      }
      if (!filled) continue;
      // Both halves must stay wide enough on every dimension.
      bool wide = true;
      for (int i = 0; i < dims(); ++i) {
        const double min_width = p_.min_dims_range_ratio * (maxs_[i] - mins_[i]);
        wide &= half[0].hi[i] - half[0].lo[i] >= min_width &&
                half[1].hi[i] - half[1].lo[i] >= min_width;
      }
      if (!wide) continue;
      for (Region& c : half) c.alp = alp_of(c.pairs);
      const double score = std::abs(half[0].alp - half[1].alp);
      if (score >= best_score) {
        best_score = score;
        best[0] = std::move(half[0]);
        best[1] = std::move(half[1]);
      }
    }
    if (best_score >= 0) {
      const int first = static_cast<int>(regions_.size());
      regions_.push_back(std::move(best[0]));
      regions_.push_back(std::move(best[1]));
      regions_[node].child[0] = first;
      regions_[node].child[1] = first + 1;
      return;
    }
    std::deque<Pair>& pairs = regions_[node].pairs;
    const auto drop = static_cast<std::size_t>(std::floor(p_.max_region_size * p_.discard_ratio));
    pairs.erase(pairs.begin(), pairs.begin() + std::min(drop, pairs.size()));
    regions_[node].alp = alp_of(pairs);
  }

  RiacParams p_;
  std::vector<Region> regions_;
};

}  // namespace

std::unique_ptr<Teacher> make_riac_teacher(std::vector<float> mins, std::vector<float> maxs,
                                           std::uint64_t seed, RiacParams params) {
  return std::make_unique<RiacTeacher>(std::move(mins), std::move(maxs), seed, params);
}

}  // namespace cradle::teach

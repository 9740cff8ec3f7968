// `cradle sami table`: the paper's Table 1/2 layout over evaluated runs, with Welch's t-tests.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/error.h"
#include "train/run_json.h"
#include "train/sami/sami_experiment.h"

namespace cradle::train {
namespace {

// The regularised incomplete beta function I_x(a, b) by its continued fraction (modified
// Lentz), on the side of x where it converges fast.
double incomplete_beta(double a, double b, double x) {
  if (x <= 0) return 0;
  if (x >= 1) return 1;
  if (x > (a + 1) / (a + b + 2)) return 1 - incomplete_beta(b, a, 1 - x);
  const double front = std::exp(std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) +
                                a * std::log(x) + b * std::log1p(-x)) /
                       a;
  constexpr double tiny = 1e-300;
  double f = 1, c = 1, d = 0;
  for (int i = 0; i <= 400; ++i) {
    const int m = i / 2;
    double numerator;
    if (i == 0) {
      numerator = 1;
    } else if (i % 2 == 0) {
      numerator = m * (b - m) * x / ((a + 2 * m - 1) * (a + 2 * m));
    } else {
      numerator = -(a + m) * (a + b + m) * x / ((a + 2 * m) * (a + 2 * m + 1));
    }
    d = 1 + numerator * d;
    d = 1 / (std::abs(d) < tiny ? tiny : d);
    c = 1 + numerator / c;
    if (std::abs(c) < tiny) c = tiny;
    f *= c * d;
    if (std::abs(1 - c * d) < 1e-14) break;
  }
  return front * (f - 1);
}

double mean_of(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

// Sample variance (n - 1).
double variance_of(const std::vector<double>& v) {
  if (v.size() < 2) return 0;
  const double m = mean_of(v);
  double s = 0;
  for (double x : v) s += (x - m) * (x - m);
  return s / static_cast<double>(v.size() - 1);
}

std::string format(double v, bool rate) {
  char buf[48];
  std::snprintf(buf, sizeof(buf), rate ? "%.2f" : "%.0f", v);
  return buf;
}

}  // namespace

Welch welch_test(const std::vector<double>& a, const std::vector<double>& b) {
  Welch w;
  if (a.size() < 2 || b.size() < 2) return {std::nan(""), std::nan(""), std::nan("")};
  const double va = variance_of(a) / a.size(), vb = variance_of(b) / b.size();
  const double se2 = va + vb;
  if (se2 == 0) return {std::nan(""), std::nan(""), std::nan("")};
  w.t = (mean_of(a) - mean_of(b)) / std::sqrt(se2);
  w.dof = se2 * se2 / (va * va / (a.size() - 1) + vb * vb / (b.size() - 1));
  w.p = incomplete_beta(w.dof / 2, 0.5, w.dof / (w.dof + w.t * w.t));
  return w;
}

std::string sami_table(const std::vector<std::filesystem::path>& runs,
                       const std::filesystem::path& out) {
  if (runs.empty()) throw UserError("sami table: no run folders given");
  // env -> method -> split -> per-seed scores.
  std::map<std::string, std::map<std::string, std::map<std::string, std::vector<double>>>> scores;
  const std::vector<std::string> splits = {"train", "moderate", "extreme"};
  // The same folder twice (or by two paths) would count one run as two seeds.
  std::map<std::filesystem::path, std::filesystem::path> seen;  // canonical -> as given
  for (const std::filesystem::path& run : runs) {
    std::error_code ec;
    if (!std::filesystem::is_directory(run, ec)) {
      throw UserError("sami table: " + run.string() +
                      " is not a folder; expected the run folder of `cradle sami train`");
    }
    const std::filesystem::path canonical = std::filesystem::weakly_canonical(run, ec);
    if (ec) throw UserError("sami table: cannot resolve " + run.string() + ": " + ec.message());
    const auto [it, fresh] = seen.emplace(canonical, run);
    if (!fresh) {
      throw UserError("sami table: " + run.string() + " is the run folder " + it->second.string() +
                      " given again; expected each run once (one seed each)");
    }
  }
  for (const std::filesystem::path& run : runs) {
    bool any = false;
    for (const std::string& split : splits) {
      const std::filesystem::path file = run / ("eval_" + split + ".json");
      std::error_code ec;
      if (!std::filesystem::exists(std::filesystem::symlink_status(file, ec))) continue;
      const RunJson j(file, "the eval_" + split + ".json of `cradle sami evaluate`");
      const std::string env = j.string("env");
      const double score = env == "PandaPush" ? j.number("success_rate") : j.number("mean_return");
      scores[env][j.string("method")][split].push_back(score);
      any = true;
    }
    if (!any) {
      throw UserError("sami table: " + run.string() +
                      " has no eval_<split>.json: run `cradle sami evaluate --run " + run.string() +
                      " --split train` first");
    }
  }
  std::ostringstream s;
  const std::vector<std::string> methods = {"TESAC", "CCM", "SaTESAC", "SaCCM", "SaCCMAll"};
  for (const auto& [env, by_method] : scores) {
    const bool rate = env == "PandaPush";
    s << "## " << env << (rate ? " (success rate" : " (mean return")
      << ", mean ± std over seeds)\n\n| method | seeds | train | moderate | extreme |\n"
      << "|---|---|---|---|---|\n";
    for (const std::string& m : methods) {
      const auto it = by_method.find(m);
      if (it == by_method.end()) continue;
      size_t seeds = 0;
      s << "| " << m;
      std::string cells;
      for (const std::string& split : splits) {
        const auto sp = it->second.find(split);
        if (sp == it->second.end()) {
          cells += " | –";
          continue;
        }
        seeds = std::max(seeds, sp->second.size());
        cells += " | " + format(mean_of(sp->second), rate) + " ± " +
                 format(std::sqrt(variance_of(sp->second)), rate);
      }
      s << " | " << seeds << cells << " |\n";
    }
    s << "\nWelch's t-test (SaMI variant minus baseline; t, p):\n\n| pair | train | moderate | "
         "extreme |\n|---|---|---|---|\n";
    for (const auto& [a, b] :
         std::vector<std::pair<std::string, std::string>>{{"SaCCM", "CCM"}, {"SaTESAC", "TESAC"}}) {
      s << "| " << a << " vs " << b;
      for (const std::string& split : splits) {
        const auto ia = by_method.find(a), ib = by_method.find(b);
        if (ia == by_method.end() || ib == by_method.end() || !ia->second.count(split) ||
            !ib->second.count(split)) {
          s << " | –";
          continue;
        }
        const Welch w = welch_test(ia->second.at(split), ib->second.at(split));
        char buf[64];
        std::snprintf(buf, sizeof(buf), " | t = %.2f, p = %.4f", w.t, w.p);
        s << (std::isnan(w.t) ? " | – (needs 2 seeds each)" : buf);
      }
      s << " |\n";
    }
    s << "\n";
  }
  if (!out.empty()) {
    std::ofstream file(out);
    file << s.str();
    if (!file) throw UserError("sami table: cannot write " + out.string());
  }
  return s.str();
}

}  // namespace cradle::train

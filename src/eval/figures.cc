#include "eval/figures.h"

#include <spawn.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <system_error>

#include "core/error.h"
#include "core/resources.h"

extern char** environ;

namespace cradle::eval {
namespace {

// Non-finite values become null (gaps).
nlohmann::json numbers(const std::vector<double>& v) {
  nlohmann::json out = nlohmann::json::array();
  for (double x : v) out.push_back(std::isfinite(x) ? nlohmann::json(x) : nlohmann::json());
  return out;
}

nlohmann::json range(const std::optional<std::pair<double, double>>& r) {
  return r ? nlohmann::json::array({r->first, r->second}) : nlohmann::json();
}

// Runs `python script spec` and returns its exit status (127 when it cannot start).
int run(const std::string& python, const std::string& script, const std::string& spec) {
  std::vector<char*> argv = {const_cast<char*>(python.c_str()), const_cast<char*>(script.c_str()),
                             const_cast<char*>(spec.c_str()), nullptr};
  pid_t pid = 0;
  if (posix_spawnp(&pid, python.c_str(), nullptr, nullptr, argv.data(), environ) != 0) return 127;
  int status = 0;
  if (waitpid(pid, &status, 0) < 0) return 127;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

}  // namespace

void Figures::add(const LinePlot& plot, const std::filesystem::path& file, int width, int height) {
  nlohmann::json series = nlohmann::json::array();
  for (const Series& s : plot.series) {
    series.push_back(
        {{"label", s.label}, {"x", numbers(s.x)}, {"y", numbers(s.y)}, {"points", s.points}});
  }
  nlohmann::json lines = nlohmann::json::array();
  for (const auto& [y, label] : plot.h_lines) lines.push_back({y, label});
  figures_.push_back({{"file", file.string()},
                      {"kind", "line"},
                      {"width", width},
                      {"height", height},
                      {"title", plot.title},
                      {"x_label", plot.x_label},
                      {"y_label", plot.y_label},
                      {"series", series},
                      {"h_lines", lines},
                      {"y_range", range(plot.y_range)}});
}

void Figures::add(const BarChart& chart, const std::filesystem::path& file, int width, int height) {
  nlohmann::json values = nlohmann::json::array();
  for (const auto& row : chart.values) values.push_back(numbers(row));
  figures_.push_back({{"file", file.string()},
                      {"kind", "bar"},
                      {"width", width},
                      {"height", height},
                      {"title", chart.title},
                      {"y_label", chart.y_label},
                      {"categories", chart.categories},
                      {"groups", chart.group_labels},
                      {"values", values},
                      {"y_range", range(chart.y_range)}});
}

bool Figures::draw(const std::filesystem::path& spec) const {
  std::error_code ec;
  if (spec.has_parent_path()) std::filesystem::create_directories(spec.parent_path(), ec);
  for (const auto& figure : figures_) {
    const std::filesystem::path file = figure["file"].get<std::string>();
    if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path(), ec);
  }
  {
    std::ofstream out(spec);
    out << nlohmann::json{{"figures", figures_}}.dump(1) << "\n";
    if (!out) throw UserError("cannot write figure spec " + spec.string());
  }
  const char* env_python = std::getenv("CRADLE_PYTHON");
  const std::string python = env_python && *env_python ? env_python : CRADLE_PYTHON;
  // An installed copy draws with its own script, a build-tree binary with the source tree's.
  const auto& installed = installed_resources();
  const std::string script = installed ? (*installed / "cradle_figures.py").string()
                                       : std::string(CRADLE_PYTHON_DIR) + "/cradle_figures.py";
  if (!std::filesystem::exists(script) || run(python, script, spec.string()) != 0) {
    std::fprintf(stderr,
                 "cradle: figures not drawn (they need %s with matplotlib and %s); their data is "
                 "in %s\n",
                 python.c_str(), script.c_str(), spec.c_str());
    return false;
  }
  return true;
}

}  // namespace cradle::eval

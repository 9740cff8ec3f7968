// Research figures (learning curves, scores, coverage, gaze angles) are drawn by Python's
// matplotlib: C++ collects what to draw, writes it as a JSON spec next to the PNGs and runs
// python/cradle_figures.py on it. Without python3 + matplotlib the spec stays (it holds every
// number) and one line on stderr says so.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace cradle::eval {

// One curve of a line plot. Non-finite points are gaps. An empty x means x = 0, 1, 2, ...
struct Series {
  std::string label;  // legend entry; empty: not in the legend
  std::vector<double> x;
  std::vector<double> y;
  bool points = false;  // scatter markers instead of a line
};

struct LinePlot {
  std::string title;
  std::string x_label;
  std::string y_label;
  std::vector<Series> series;
  std::optional<std::pair<double, double>> y_range;  // default: matplotlib's
  // Dashed horizontal reference lines with labels, e.g. {15, "central field of view"}.
  std::vector<std::pair<double, std::string>> h_lines;
};

struct BarChart {
  std::string title;
  std::string y_label;
  std::vector<std::string> categories;      // x labels
  std::vector<std::string> group_labels;    // legend, one per group
  std::vector<std::vector<double>> values;  // values[group][category]; NaN: no bar
  std::optional<std::pair<double, double>> y_range;
};

class Figures {
 public:
  void add(const LinePlot& plot, const std::filesystem::path& file, int width = 900,
           int height = 540);
  void add(const BarChart& chart, const std::filesystem::path& file, int width = 900,
           int height = 540);
  bool empty() const { return figures_.empty(); }
  // Writes the spec (parents created; UserError if it cannot) and draws every figure with
  // `python` (default: $CRADLE_PYTHON, else the build's Python) running cradle_figures.py.
  // Returns false, after one line on stderr, when they could not be drawn.
  bool draw(const std::filesystem::path& spec) const;

 private:
  nlohmann::json figures_ = nlohmann::json::array();
};

}  // namespace cradle::eval

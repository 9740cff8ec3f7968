// PNG charts without Python: line plots (scores over episodes, learning curves, gaze-hand angle
// over time) and grouped bar charts (touch coverage per body part), drawn by a small antialiased
// rasterizer with the stb_easy_font bitmap font.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "model/textures.h"

namespace cradle::eval {

struct Rgb {
  std::uint8_t r = 0;
  std::uint8_t g = 0;
  std::uint8_t b = 0;
};

// One curve of a line plot. Points with a non-finite x or y are skipped and break the line. An
// empty x means x = 0, 1, 2, ... (the index of each y).
struct Series {
  std::string label;  // legend entry; empty: not in the legend
  std::vector<double> x;
  std::vector<double> y;
  Rgb color;
  bool points = false;  // scatter markers instead of a line
};

struct LinePlot {
  std::string title;
  std::string x_label;
  std::string y_label;
  std::vector<Series> series;
  std::optional<std::pair<double, double>> x_range;  // default: the data's
  std::optional<std::pair<double, double>> y_range;  // default: the data's with a margin
  // Dashed horizontal reference lines with labels, e.g. {15, "threshold 15°"}.
  std::vector<std::pair<double, std::string>> h_lines;
};

struct BarChart {
  std::string title;
  std::string y_label;
  std::vector<std::string> categories;      // x labels; slanted when they do not fit side by side
  std::vector<std::string> group_labels;    // legend, one per group
  std::vector<std::vector<double>> values;  // values[group][category]; missing or NaN: no bar
  std::vector<Rgb> colors;                  // per group; missing: default_color(group)
  std::optional<std::pair<double, double>> y_range;  // default: 0 and the data's extremes
};

// Colour i of a ten-colour palette that tells series apart (cycles).
Rgb default_color(int i);

// Evenly spaced round tick values (steps 1, 2 or 5 times a power of ten) from a multiple of the
// step at or below lo to one at or above hi, about `target` intervals.
std::vector<double> nice_ticks(double lo, double hi, int target = 5);

// Short labels for evenly spaced ticks: "0.25", "2.5k", "3M", "1e-3", "-2.5e-4".
std::vector<std::string> tick_labels(const std::vector<double>& ticks);

model::Image render_line_plot(const LinePlot& plot, int width = 900, int height = 540);
model::Image render_bar_chart(const BarChart& chart, int width = 900, int height = 540);

// Writes an image as PNG, creating missing parent folders; throws UserError if it cannot.
void write_png(const model::Image& image, const std::filesystem::path& file);

}  // namespace cradle::eval

// Tests of the PNG chart rasterizer: nice ticks and their labels, where lines and bars land in
// the image, text, PNG files, and edge cases (no data, NaN, one point, extreme magnitudes).
#include "eval/plot.h"

#include <gtest/gtest.h>
#include <stb_image.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "core/error.h"

namespace cradle::eval {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr Rgb kRed{255, 0, 0};
constexpr Rgb kGreen{0, 160, 0};
constexpr Rgb kBlue{0, 0, 255};

// Colour of pixel (x, y).
Rgb pixel(const model::Image& image, int x, int y) {
  const std::size_t i = 3 * (static_cast<std::size_t>(y) * image.width + x);
  return {image.rgb[i], image.rgb[i + 1], image.rgb[i + 2]};
}

bool same(Rgb a, Rgb b) { return a.r == b.r && a.g == b.g && a.b == b.b; }

// Pixels close to a colour (antialiased edges are blends towards white, so only strong ones).
bool near(Rgb a, Rgb b) {
  return std::abs(a.r - b.r) < 60 && std::abs(a.g - b.g) < 60 && std::abs(a.b - b.b) < 60;
}

// Whether any pixel in [x0, x1) x [y0, y1) is close to a colour.
bool any_near(const model::Image& image, Rgb c, int x0, int y0, int x1, int y1) {
  for (int y = std::max(0, y0); y < std::min(image.height, y1); ++y) {
    for (int x = std::max(0, x0); x < std::min(image.width, x1); ++x) {
      if (near(pixel(image, x, y), c)) return true;
    }
  }
  return false;
}

// Whether any pixel in rows [y0, y1) is not white.
bool any_ink(const model::Image& image, int y0, int y1) {
  for (int y = y0; y < y1; ++y) {
    for (int x = 0; x < image.width; ++x) {
      if (!same(pixel(image, x, y), {255, 255, 255})) return true;
    }
  }
  return false;
}

// Heights of the bars of one exact colour, left to right: per run of columns holding the colour,
// the most pixels of it in one column.
std::vector<int> bar_heights(const model::Image& image, Rgb c) {
  std::vector<int> heights;
  bool in_bar = false;
  for (int x = 0; x < image.width; ++x) {
    int count = 0;
    for (int y = 0; y < image.height; ++y) count += same(pixel(image, x, y), c);
    if (count > 0 && !in_bar) heights.push_back(0);
    if (count > 0) heights.back() = std::max(heights.back(), count);
    in_bar = count > 0;
  }
  return heights;
}

void expect_ticks(const std::vector<double>& got, const std::vector<double>& want) {
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < got.size(); ++i) EXPECT_NEAR(got[i], want[i], 1e-12) << i;
}

TEST(NiceTicks, RoundSteps) {
  expect_ticks(nice_ticks(0, 1), {0, 0.2, 0.4, 0.6, 0.8, 1});
  expect_ticks(nice_ticks(0, 37), {0, 10, 20, 30, 40});
  expect_ticks(nice_ticks(1, 0), {0, 0.2, 0.4, 0.6, 0.8, 1});
  expect_ticks(nice_ticks(-1.85, 38.85), {-10, 0, 10, 20, 30, 40});
}

TEST(NiceTicks, SmallRangeCoveredWithOneTwoFiveSteps) {
  const std::vector<double> ticks = nice_ticks(-3e-4, 7e-4);
  ASSERT_GE(ticks.size(), 4u);
  ASSERT_LE(ticks.size(), 9u);
  EXPECT_LE(ticks.front(), -3e-4);
  EXPECT_GE(ticks.back(), 7e-4);
  const double step = ticks[1] - ticks[0];
  const double mantissa = step / std::pow(10.0, std::floor(std::log10(step)));
  EXPECT_TRUE(std::abs(mantissa - 1) < 1e-9 || std::abs(mantissa - 2) < 1e-9 ||
              std::abs(mantissa - 5) < 1e-9)
      << step;
  EXPECT_NE(std::find(ticks.begin(), ticks.end(), 0.0), ticks.end());
}

TEST(NiceTicks, DegenerateAndNonFinite) {
  const std::vector<double> ticks = nice_ticks(5, 5);
  ASSERT_GE(ticks.size(), 2u);
  EXPECT_LT(ticks.front(), 5);
  EXPECT_GT(ticks.back(), 5);
  EXPECT_GE(nice_ticks(0, 0).size(), 2u);
  EXPECT_TRUE(nice_ticks(kNaN, 1).empty());
  EXPECT_TRUE(nice_ticks(0, kInf).empty());
  EXPECT_LE(nice_ticks(1e300, 1.5e300).size(), 12u);
}

TEST(TickLabels, PlainSuffixedAndScientific) {
  EXPECT_EQ(tick_labels({0, 0.2, 0.4}), (std::vector<std::string>{"0.0", "0.2", "0.4"}));
  EXPECT_EQ(tick_labels({0, 10, 20}), (std::vector<std::string>{"0", "10", "20"}));
  EXPECT_EQ(tick_labels({0, 2500, 5000, 7500, 10000}),
            (std::vector<std::string>{"0", "2.5k", "5k", "7.5k", "10k"}));
  EXPECT_EQ(tick_labels({-1e6, 0, 1e6, 2e6}), (std::vector<std::string>{"-1M", "0", "1M", "2M"}));
  EXPECT_EQ(tick_labels({-4e-4, -2e-4, 0, 2e-4, 1e-3}),
            (std::vector<std::string>{"-4e-4", "-2e-4", "0", "2e-4", "1e-3"}));
  EXPECT_EQ(tick_labels({1.5e-3, 2.5e-3}), (std::vector<std::string>{"1.5e-3", "2.5e-3"}));
  EXPECT_TRUE(tick_labels({}).empty());
}

TEST(DefaultColor, CyclesAndDiffers) {
  EXPECT_TRUE(same(default_color(0), default_color(10)));
  EXPECT_TRUE(same(default_color(-1), default_color(9)));
  EXPECT_FALSE(same(default_color(0), default_color(1)));
}

TEST(LinePlot, IdentityLineRisesToTheRight) {
  LinePlot plot{.title = "y = x", .x_label = "x", .y_label = "y"};
  plot.series.push_back({.x = {0, 0.5, 1}, .y = {0, 0.5, 1}, .color = kRed});
  const model::Image image = render_line_plot(plot);
  ASSERT_EQ(image.width, 900);
  ASSERT_EQ(image.height, 540);
  ASSERT_EQ(image.rgb.size(), 900u * 540u * 3u);

  // Extent of the strongly red pixels: a wide diagonal band.
  int x0 = image.width, x1 = -1, y0 = image.height, y1 = -1;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      if (!same(pixel(image, x, y), kRed)) continue;
      x0 = std::min(x0, x);
      x1 = std::max(x1, x);
      y0 = std::min(y0, y);
      y1 = std::max(y1, y);
    }
  }
  ASSERT_GE(x1, 0) << "no red pixels";
  EXPECT_GT(x1 - x0, image.width * 3 / 4);
  EXPECT_GT(y1 - y0, image.height / 2);
  const int w = x1 - x0, h = y1 - y0;
  // Red near the lower left and the upper right of its extent, none at the other two corners.
  EXPECT_TRUE(any_near(image, kRed, x0, y1 - h / 10, x0 + w / 10, y1 + 1));
  EXPECT_TRUE(any_near(image, kRed, x1 - w / 10, y0, x1 + 1, y0 + h / 10));
  EXPECT_FALSE(any_near(image, kRed, x1 - w / 4, y1 - h / 4, x1 + 1, y1 + 1));
  EXPECT_FALSE(any_near(image, kRed, x0, y0, x0 + w / 4, y0 + h / 4));
  // The middle of the line is near the middle of its extent.
  EXPECT_TRUE(
      any_near(image, kRed, x0 + w / 2 - 3, y0 + h / 2 - 3, x0 + w / 2 + 4, y0 + h / 2 + 4));
}

TEST(LinePlot, LinesAreAboutTwoPixelsThick) {
  LinePlot plot;
  plot.series.push_back({.x = {0, 1}, .y = {0.5, 0.5}, .color = kBlue});
  plot.y_range = {{0, 1}};
  const model::Image image = render_line_plot(plot);
  // Count blue-ish pixels down the middle column.
  int count = 0;
  for (int y = 0; y < image.height; ++y) {
    const Rgb p = pixel(image, image.width / 2, y);
    count += p.b > 200 && p.r < 160;
  }
  EXPECT_GE(count, 2);
  EXPECT_LE(count, 3);
}

TEST(LinePlot, TitleAndLabelsRenderText) {
  LinePlot untitled;
  untitled.series.push_back({.x = {0, 1}, .y = {0, 1}, .color = kRed});
  LinePlot titled = untitled;
  titled.title = "Score over training";
  const model::Image plain = render_line_plot(untitled);
  const model::Image with_title = render_line_plot(titled);
  EXPECT_FALSE(any_ink(plain, 0, 8));
  EXPECT_TRUE(any_ink(with_title, 0, 40));
  // Axis labels: text left of the tick labels and below the x tick labels.
  titled.x_label = "episode";
  titled.y_label = "score";
  const model::Image labelled = render_line_plot(titled);
  EXPECT_TRUE(any_ink(labelled, labelled.height - 20, labelled.height));
  EXPECT_NE(labelled.rgb, with_title.rgb);
}

TEST(LinePlot, LegendShowsLabelledSeries) {
  LinePlot plot;
  plot.series.push_back({.label = "right hand", .x = {0, 1}, .y = {0, 1}, .color = kGreen});
  plot.series.push_back({.x = {0, 1}, .y = {1, 0}, .color = kBlue});
  const model::Image with_legend = render_line_plot(plot);
  plot.series[0].label.clear();
  const model::Image without = render_line_plot(plot);
  EXPECT_NE(with_legend.rgb, without.rgb);
}

TEST(LinePlot, ReferenceLineIsDrawn) {
  LinePlot plot;
  plot.series.push_back({.x = {0, 1}, .y = {0, 90}, .color = kBlue});
  const model::Image before = render_line_plot(plot);
  plot.h_lines = {{15, "threshold 15°"}};
  const model::Image after = render_line_plot(plot);
  EXPECT_NE(before.rgb, after.rgb);
}

TEST(LinePlot, EdgeCasesDoNotCrash) {
  const auto check = [](const LinePlot& plot) {
    const model::Image image = render_line_plot(plot, 640, 400);
    EXPECT_EQ(image.rgb.size(), 640u * 400u * 3u);
  };
  LinePlot empty{.title = "empty"};
  check(empty);
  empty.series.push_back({.label = "nothing", .color = kRed});
  check(empty);
  check({.series = {{.x = {kNaN, kInf}, .y = {1, kNaN}, .color = kRed}}});
  check({.series = {{.x = {3}, .y = {5}, .color = kRed}}});
  check({.series = {{.x = {0, 1, 2}, .y = {7, 7, 7}, .color = kRed}}});
  check({.series = {{.x = {0, 1, 2}, .y = {0, 0, 0}, .color = kRed, .points = true}}});
  check({.series = {{.x = {0, 1, 2, 3}, .y = {1, kNaN, 3, -kInf}, .color = kRed}}});
  check({.series = {{.x = {0, 1}, .y = {-1e308, 1e308}, .color = kRed}}});
  check({.series = {{.x = {0, 1}, .y = {1e-300, 3e-300}, .color = kRed}}});
  check({.series = {{.x = {0, 1e-320}, .y = {0, 5e-324}, .color = kRed}}});
  check({.series = {{.x = {1, 2, 3}, .y = {1}, .color = kRed}}});
  check({.series = {{.y = {3, 1, 2}, .color = kRed}}});
  check({.series = {{.x = {0, 1}, .y = {0, 1e300}, .color = kRed}}, .y_range = {{0, 1}}});
  check({.series = {{.x = {0, 1}, .y = {0, 1}, .color = kRed}}, .y_range = {{2, 2}}});
  check({.series = {{.x = {0, 1}, .y = {0, 1}, .color = kRed}}, .y_range = {{1, 0}}});
  check({.series = {{.x = {0, 1}, .y = {0, 1}, .color = kRed}}, .y_range = {{kNaN, 1}}});
  check({.h_lines = {{kNaN, "bad"}, {1e9, "far"}}});
  check({.title = std::string(500, 'W'),
         .x_label = std::string(300, 'x'),
         .y_label = "\xff\xfe bytes \xc2\xb0 \xe2\x82\xac"});
  EXPECT_THROW(render_line_plot({}, 10, 10), UserError);
}

TEST(LinePlot, OtherSizes) {
  LinePlot plot{.title = "t", .x_label = "x", .y_label = "y"};
  plot.series.push_back({.label = "a", .x = {0, 1}, .y = {0, 1}, .color = kRed});
  for (const auto& [w, h] : {std::pair{160, 100}, {320, 200}, {1920, 1080}}) {
    const model::Image image = render_line_plot(plot, w, h);
    EXPECT_EQ(image.width, w);
    EXPECT_EQ(image.height, h);
    EXPECT_EQ(image.rgb.size(), static_cast<std::size_t>(w) * h * 3);
  }
}

TEST(LinePlot, HundredThousandPointsAreFast) {
  Series line{.label = "return", .color = kBlue};
  for (int i = 0; i < 100000; ++i) {
    line.x.push_back(i);
    line.y.push_back(std::sin(i * 1e-3) + 0.3 * std::sin(i * 7.77));
  }
  Series scatter = line;
  scatter.points = true;
  for (const Series& s : {line, scatter}) {
    const auto start = std::chrono::steady_clock::now();
    const model::Image image = render_line_plot({.series = {s}});
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    EXPECT_EQ(image.width, 900);
    // About 30 ms in a release build; the bound leaves room for debug builds and busy machines.
    EXPECT_LT(ms, 1000) << (s.points ? "scatter" : "line");
  }
}

TEST(BarChart, HeightsAreProportionalToValues) {
  BarChart chart{.title = "coverage", .y_label = "fraction"};
  chart.categories = {"head", "hand", "foot"};
  chart.values = {{1, 2, 0.5}, {2, 1, 1.5}};
  chart.colors = {kRed, kBlue};
  const model::Image image = render_bar_chart(chart);
  const std::vector<int> red = bar_heights(image, kRed);
  const std::vector<int> blue = bar_heights(image, kBlue);
  ASSERT_EQ(red.size(), 3u);
  ASSERT_EQ(blue.size(), 3u);
  const double unit = red[0];
  EXPECT_GT(unit, 50);
  EXPECT_NEAR(red[1], 2 * unit, 3);
  EXPECT_NEAR(red[2], 0.5 * unit, 3);
  EXPECT_NEAR(blue[0], 2 * unit, 3);
  EXPECT_NEAR(blue[1], unit, 3);
  EXPECT_NEAR(blue[2], 1.5 * unit, 3);
}

TEST(BarChart, LegendAndLongCategoryNames) {
  BarChart chart{.title = "Touch coverage per body part", .y_label = "fraction touched"};
  for (int i = 0; i < 20; ++i) chart.categories.push_back("right_upper_arm_" + std::to_string(i));
  chart.group_labels = {"right hand", "left hand"};
  chart.values = {std::vector<double>(20, 0.3), std::vector<double>(20, 0.6)};
  const model::Image image = render_bar_chart(chart);
  // Twenty bars in each default colour, each colour also in the legend under the title.
  EXPECT_EQ(bar_heights(image, default_color(0)).size(), 20u);
  EXPECT_EQ(bar_heights(image, default_color(1)).size(), 20u);
  model::Image top = image;
  top.height = 75;
  top.rgb.resize(3u * top.width * top.height);
  EXPECT_EQ(bar_heights(top, default_color(0)).size(), 1u);
  EXPECT_EQ(bar_heights(top, default_color(1)).size(), 1u);
  // Slanted category names below the plot.
  EXPECT_TRUE(any_ink(image, image.height - 60, image.height));
}

TEST(BarChart, EdgeCasesDoNotCrash) {
  const auto check = [](const BarChart& chart) {
    const model::Image image = render_bar_chart(chart, 640, 400);
    EXPECT_EQ(image.rgb.size(), 640u * 400u * 3u);
  };
  check({});
  check({.title = "no values", .categories = {"a", "b"}});
  check({.categories = {"a", "b"}, .values = {{kNaN, kInf}}});
  check({.categories = {"a", "b", "c"}, .values = {{1}, {2, 3, 4, 5}}});
  check({.categories = {"a", "b"}, .values = {{-1, 2}, {-3, 0.5}}, .colors = {kRed}});
  check({.categories = {"a", "b"}, .values = {{0, 0}}});
  check({.categories = {"a"}, .values = {{1e300}}, .y_range = {{0, 1}}});
  check({.categories = {"a", "b"}, .values = {{-1e308, 1e308}}});
  check({.categories = {"a"}, .group_labels = {"g1", "g2", "g3"}, .values = {{1}}});
  check({.categories = std::vector<std::string>(200, std::string(60, 'n')),
         .values = {std::vector<double>(200, 1)}});
  EXPECT_THROW(render_bar_chart({}, 100, 20), UserError);
}

// A fresh folder under the system temp folder, removed at the end of the test.
class PngFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ =
        std::filesystem::temp_directory_path() / ("cradle_plot_test_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::filesystem::path dir_;
};

TEST_F(PngFile, WritesDecodablePng) {
  LinePlot plot{.title = "t"};
  plot.series.push_back({.x = {0, 1}, .y = {0, 1}, .color = kRed});
  const model::Image image = render_line_plot(plot, 400, 300);
  const std::filesystem::path file = dir_ / "nested" / "plot.png";
  write_png(image, file);
  ASSERT_TRUE(std::filesystem::exists(file));
  int width = 0, height = 0, channels = 0;
  stbi_uc* decoded = stbi_load(file.c_str(), &width, &height, &channels, 3);
  ASSERT_NE(decoded, nullptr);
  EXPECT_EQ(width, 400);
  EXPECT_EQ(height, 300);
  EXPECT_TRUE(std::equal(image.rgb.begin(), image.rgb.end(), decoded));
  stbi_image_free(decoded);
}

TEST_F(PngFile, UnwritablePathThrowsUserError) {
  const model::Image image = render_bar_chart({}, 200, 120);
  // A regular file where a folder is expected cannot be written into, even by root.
  std::filesystem::create_directories(dir_);
  std::ofstream(dir_ / "blocker") << "x";
  EXPECT_THROW(write_png(image, dir_ / "blocker" / "plot.png"), UserError);
  EXPECT_THROW(write_png(image, dir_), UserError);  // a folder, not a file
  EXPECT_THROW(write_png(model::Image{}, dir_ / "empty.png"), UserError);
}

}  // namespace
}  // namespace cradle::eval

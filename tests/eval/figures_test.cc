// Research figures: the JSON spec holds every number (non-finite values as gaps) and Debian's
// python3 with matplotlib (an install-deps package) draws PNGs of the asked size from it; without
// the interpreter draw() says so and keeps the spec.
#include "eval/figures.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>

namespace cradle::eval {
namespace {

namespace fs = std::filesystem;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

fs::path fresh_dir(const char* name) {
  const fs::path dir =
      fs::temp_directory_path() / (std::string("cradle_") + name + "_" + std::to_string(getpid()));
  fs::remove_all(dir);
  return dir;
}

// Width and height from a PNG's IHDR chunk (big-endian at bytes 16 and 20); 0 x 0 if not a PNG.
std::pair<int, int> png_size(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  unsigned char head[24] = {};
  in.read(reinterpret_cast<char*>(head), sizeof head);
  if (!in || head[1] != 'P' || head[2] != 'N' || head[3] != 'G') return {0, 0};
  auto be32 = [&](int at) {
    return (head[at] << 24) | (head[at + 1] << 16) | (head[at + 2] << 8) | head[at + 3];
  };
  return {be32(16), be32(20)};
}

void add_two(Figures& figures, const fs::path& dir) {
  figures.add(LinePlot{.title = "y = x",
                       .x_label = "x",
                       .y_label = "y",
                       .series = {{.label = "a", .x = {0, 1, 2}, .y = {0, kNaN, 2}}},
                       .h_lines = {{1.5, "threshold"}}},
              dir / "line.png", 640, 400);
  figures.add(BarChart{.title = "coverage",
                       .categories = {"hip", "head"},
                       .group_labels = {"right hand", "left hand"},
                       .values = {{0.5, 1}, {0.25, kNaN}},
                       .y_range = std::pair{0.0, 1.0}},
              dir / "bar.png");
}

TEST(Figures, SpecHoldsTheNumbersAndMatplotlibDrawsThem) {
  const fs::path dir = fresh_dir("figures");
  Figures figures;
  EXPECT_TRUE(figures.empty());
  add_two(figures, dir);
  const bool drawn = figures.draw(dir / "figures.json");

  std::ifstream in(dir / "figures.json");
  const nlohmann::json spec = nlohmann::json::parse(in);
  ASSERT_EQ(spec["figures"].size(), 2u);
  const nlohmann::json& line = spec["figures"][0];
  EXPECT_EQ(line["kind"], "line");
  EXPECT_EQ(line["series"][0]["y"][0], 0.0);
  EXPECT_TRUE(line["series"][0]["y"][1].is_null());  // NaN: a gap
  EXPECT_EQ(line["series"][0]["y"][2], 2.0);
  EXPECT_EQ(line["h_lines"][0][1], "threshold");
  const nlohmann::json& bar = spec["figures"][1];
  EXPECT_EQ(bar["categories"][1], "head");
  EXPECT_TRUE(bar["values"][1][1].is_null());
  EXPECT_EQ(bar["y_range"][1], 1.0);

  EXPECT_TRUE(drawn);
  EXPECT_EQ(png_size(dir / "line.png"), std::make_pair(640, 400));
  EXPECT_EQ(png_size(dir / "bar.png"), std::make_pair(900, 540));
  fs::remove_all(dir);
}

TEST(Figures, WithoutPythonTheSpecStays) {
  const fs::path dir = fresh_dir("figures_nopy");
  Figures figures;
  add_two(figures, dir);
  ::setenv("CRADLE_PYTHON", "/nonexistent/python3", 1);
  testing::internal::CaptureStderr();
  const bool drawn = figures.draw(dir / "figures.json");
  const std::string message = testing::internal::GetCapturedStderr();
  ::unsetenv("CRADLE_PYTHON");
  EXPECT_FALSE(drawn);
  EXPECT_NE(message.find("figures not drawn"), std::string::npos) << message;
  EXPECT_EQ(std::count(message.begin(), message.end(), '\n'), 1) << message;
  EXPECT_TRUE(fs::exists(dir / "figures.json"));
  EXPECT_FALSE(fs::exists(dir / "line.png"));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace cradle::eval

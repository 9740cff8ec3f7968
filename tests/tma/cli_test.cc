// `cradle tma`: info lists every embodiment, random writes a video and a PNG, bad input is a
// one-line error with exit status 1.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "fixture.h"

namespace {

namespace fs = std::filesystem;

using cradle::test::run_cradle;
using cradle::test::RunResult;

TEST(TmaCli, InfoListsEveryEmbodiment) {
  const RunResult r = run_cradle("tma info");
  ASSERT_EQ(r.status, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.size(), 13u);
  EXPECT_EQ(j[0]["embodiment"], "old_classic_bipedal");
  EXPECT_EQ(j[0]["observation_size"]["parkour"], 36);
}

TEST(TmaCli, RandomWritesVideoAndPng) {
  const fs::path dir = fs::temp_directory_path() / "cradle_tma_cli_test";
  fs::create_directories(dir);
  const RunResult r = run_cradle(
      "tma random --env parkour --embodiment fish --task input_vector=0,0,0 --task "
      "water_level=1 --steps 20 --video " +
      (dir / "fish.mp4").string() + " --png " + (dir / "fish.png").string() + " --png-step 5");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("20 steps"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("(21 frames)"), std::string::npos) << r.out;
  EXPECT_GT(fs::file_size(dir / "fish.mp4"), 1000u);
  EXPECT_GT(fs::file_size(dir / "fish.png"), 1000u);
  fs::remove_all(dir);
}

TEST(TmaCli, BadInputIsOneLineError) {
  for (const char* args :
       {"tma random --embodiment centipede", "tma random --env hexagon",
        "tma random --task stump_height=abc", "tma random --task stump_height=20",
        "tma random --env parkour --task input_vector=0,0", "tma bench --embodiment nope"}) {
    const RunResult r = run_cradle(args);
    EXPECT_EQ(r.status, 1) << args;
    EXPECT_EQ(r.out.rfind("cradle: error: ", 0), 0u) << args << ": " << r.out;
    EXPECT_EQ(r.out.find('\n'), r.out.size() - 1) << args << ": " << r.out;
  }
}

}  // namespace

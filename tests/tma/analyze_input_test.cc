// `cradle tma analyze` on input that is no campaign or a damaged one (python/cradle/
// tma_analysis.py reads it): exit 1 with one line naming the folder or file and what was expected,
// no Python traceback, no second line, and no analysis folder written.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include "fixture.h"

namespace {

namespace fs = std::filesystem;

using cradle::test::run_cradle;
using cradle::test::RunResult;

// A synthetic results tree (Random and ALP-GMM on criterion 1, 2 seeds each) under `root`.
void synthetic_tree(const fs::path& root) {
  const RunResult r = cradle::test::run(
      std::string("/usr/bin/python3 -c \"import sys; sys.path.insert(0, '") + CRADLE_SOURCE_DIR +
      "/python/cradle'); import tma_analysis as ta; ta.make_synthetic_results('" + root.string() +
      "', seeds=2, experiments=('criterion_1',), evaluations=11, test_tasks=4, "
      "episodes_per_eval=2)\" 2>&1");
  ASSERT_EQ(r.status, 0) << r.out;
}

const fs::path kRun =
    "Random_criterion_1_old_classic_bipedal/Random_criterion_1_old_classic_bipedal_s0";

void expect_one_line(const fs::path& results, const std::vector<std::string>& needles) {
  const fs::path out = results.parent_path() / "analysis";
  const RunResult r = run_cradle("tma analyze " + results.string() + " --out " + out.string());
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_EQ(r.out.rfind("cradle: error: ", 0), 0u) << r.out;
  EXPECT_EQ(r.out.find('\n'), r.out.size() - 1) << r.out;
  EXPECT_EQ(r.out.find("Traceback"), std::string::npos) << r.out;
  for (const std::string& n : needles)
    EXPECT_NE(r.out.find(n), std::string::npos) << n << "\n" << r.out;
  EXPECT_FALSE(fs::exists(out));
}

TEST(TmaAnalyzeInput, NoCampaignIsOneLine) {
  const fs::path dir = cradle::test::fresh_dir("tma_analyze_none");
  fs::create_directories(dir / "empty");
  expect_one_line(dir / "empty", {(dir / "empty").string(), "no run folder with a progress.csv"});
  fs::create_directories(dir / "other" / "sub");
  std::ofstream(dir / "other" / "notes.txt") << "hello\n";
  expect_one_line(dir / "other", {(dir / "other").string(), "expected the results tree"});
  std::ofstream(dir / "file") << "x\n";
  expect_one_line(dir / "file", {(dir / "file").string(), "is not a folder"});
  expect_one_line(dir / "missing", {(dir / "missing").string(), "does not exist"});
  fs::remove_all(dir);
}

TEST(TmaAnalyzeInput, DamagedRunFilesAreOneLineNamingTheFile) {
  const fs::path dir = cradle::test::fresh_dir("tma_analyze_damaged");
  struct Case {
    const char* file;
    std::function<void(const fs::path&)> damage;
    const char* says;
  };
  const auto cut = [](const fs::path& f) { fs::resize_file(f, fs::file_size(f) - 15); };
  const auto folder = [](const fs::path& f) {
    fs::remove(f);
    fs::create_directories(f);
  };
  const auto append = [](const std::string& text) {
    return [text](const fs::path& f) { std::ofstream(f, std::ios::app) << text; };
  };
  const std::vector<Case> cases = {
      {"progress.csv", cut, "is truncated"},
      {"progress.csv", append("1,abc,0,0,0,0,0,0,0\n"), "column env_steps: 'abc' is not a number"},
      {"progress.csv", append("1,2\n"), "has 2 cells, the header 9"},
      {"progress.csv", folder, "is a folder"},
      {"test_returns.csv", cut, "is truncated"},
      {"test_returns.csv", append("1,2,3,x,1\n"), "column return: 'x' is not a number"},
      {"test_returns.csv", folder, "is a folder"},
  };
  for (const Case& c : cases) {
    const fs::path results = dir / "results";
    fs::remove_all(results);
    synthetic_tree(results);
    const fs::path file = results / kRun / c.file;
    ASSERT_TRUE(fs::exists(file)) << file;
    c.damage(file);
    expect_one_line(results, {file.string(), c.says});
  }
  fs::remove_all(dir);
}

}  // namespace

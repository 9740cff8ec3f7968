// Hostile but fair input to the `cradle` binary: every bad flag, seed, hyperparameter, config
// file and training-log line is one line on stderr and exit 1, quickly.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "fixture.h"

namespace {

namespace fs = std::filesystem;

struct CliRun : cradle::test::RunResult {
  double seconds = 0;  // CPU time of the command
};

// CPU seconds of the finished child processes so far.
double children_cpu_seconds() {
  rusage usage{};
  getrusage(RUSAGE_CHILDREN, &usage);
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec +
         (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec) / 1e6;
}

// `cradle <args>` through the shared runner, with no input (a command that waited on stdin would
// hang the test instead of failing it), timed in CPU seconds: a command that works too long shows
// in them, while waiting for a core on a loaded machine does not.
CliRun cradle(const std::string& args) {
  const double start = children_cpu_seconds();
  CliRun r{cradle::test::run_cradle(args + " </dev/null")};
  r.seconds = children_cpu_seconds() - start;
  return r;
}

fs::path temp_dir(const std::string& tag) { return cradle::test::fresh_dir("robust_" + tag); }

// How many message lines the output holds.
int message_count(const std::string& out) {
  return static_cast<int>(cradle::test::message_lines(out).size());
}

void expect_one_line_error(const std::string& args) {
  const CliRun r = cradle(args);
  EXPECT_EQ(r.status, 1) << args << "\n" << r.out;
  EXPECT_EQ(message_count(r.out), 1) << args << "\n" << r.out;
  EXPECT_EQ(r.out.rfind("cradle: error: ", 0), 0u) << args << "\n" << r.out;
  EXPECT_LT(r.seconds, 60) << args;
}

std::string quick_config(const fs::path& dir) { return cradle::test::self_touch_config(dir, 100); }

TEST(Robust, FlagParseErrorsAreOneLineExitOne) {
  const fs::path dir = temp_dir("flags");
  const std::string train = "train --config " + quick_config(dir) + " --eval-episodes 0";
  for (const std::string& args :
       {train + " --seed -1", train + " --seed 18446744073709551616", train + " --seed 1.5",
        train + " --seed abc", train + " --envs 0", train + " --steps abc", train + " --no-such",
        train + " --algo nope", std::string("no-such-command"), std::string(""),
        std::string("illustrate --envs 100000 --env reach"),
        "evaluate --config " + quick_config(dir) + " --seed -5",
        std::string("launch --nproc 1 --grace nan -- true"),
        std::string("launch --nproc 1 --grace inf -- true")}) {
    expect_one_line_error(args);
  }
  EXPECT_EQ(cradle("--version").status, 0);
  EXPECT_EQ(cradle("train --help").status, 0);
  fs::remove_all(dir);
}

TEST(Robust, BadHyperparametersAreRefusedUpFront) {
  const fs::path dir = temp_dir("hp");
  const std::string train = "train --config " + quick_config(dir) +
                            " --envs 1 --steps 64 --eval-episodes 0 --intrinsic '' --hp n_steps=64";
  // Through the binary for a few; learn_test's HyperparameterRanges covers every learner.
  for (const char* hp : {"learning_rate=nan", "gamma=2", "batch_size=0"}) {
    expect_one_line_error(train + " " + std::string(hp));
  }
  fs::remove_all(dir);
}

TEST(Robust, BadConfigFilesAreOneLineErrors) {
  const fs::path dir = temp_dir("files");
  std::ofstream(dir / "big.yml") << std::string(2 << 20, '#');
  std::ofstream(dir / "noact.yml") << "act_hands: False\nact_fingers: False\nact_arms: False\n"
                                      "act_feet: False\nact_legs: False\nact_body: False\n"
                                      "act_head: False\nact_eyes: False\n";
  std::ofstream(dir / "skip.yml") << "frame_skip: 2147483647\n";
  std::ofstream(dir / "touch.yml") << "touch_scale: 0.001\n";
  for (const std::string& file :
       {std::string("/dev/zero"), std::string("/proc/self/mem"), dir.string(),
        (dir / "missing.yml").string(), (dir / "big.yml").string(), (dir / "noact.yml").string(),
        (dir / "skip.yml").string(), (dir / "touch.yml").string()}) {
    expect_one_line_error("model-info --config " + file);
  }
  fs::remove_all(dir);
}

// Lines of training.jsonl that are JSON but no entry, or name geoms the model lacks.
TEST(Robust, BadTrainingLogLinesNameTheirLine) {
  const fs::path dir = temp_dir("log");
  const std::string config = quick_config(dir);
  fs::create_directories(dir / "run" / "logs");
  for (const char* bad :
       {"42", "[1,2,3]", R"({"steps":"many"})", R"({"steps":10,"right_hand_touches":[100000]})",
        R"({"steps":10,"left_hand_touches":"x"})"}) {
    std::ofstream(dir / "run" / "logs" / "training.jsonl")
        << "{\"steps\":0,\"right_hand_touches\":[],\"left_hand_touches\":[]}\n"
        << bad << "\n";
    const CliRun r =
        cradle("evaluate --config " + config + " --episodes 1 --duration 2 --no-render");
    EXPECT_EQ(r.status, 1) << bad << "\n" << r.out;
    EXPECT_EQ(message_count(r.out), 1) << bad << "\n" << r.out;
    EXPECT_NE(r.out.find("training.jsonl:2:"), std::string::npos) << bad << "\n" << r.out;
  }
  fs::remove_all(dir);
}

}  // namespace

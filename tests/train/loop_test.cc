// The shared training loop: learn() returns at each boundary (a multiple of boundary_every), the
// run acts there unless it is done, a report or the stop flag ends it, and a learner that cannot
// advance does not hang it.
#include "train/loop.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace cradle::train {
namespace {

// A learner that advances `per_report` steps per report (0: never) and counts its learn() calls.
class CountingLearner final : public learn::Learner {
 public:
  explicit CountingLearner(long per_report, long start = 0)
      : per_report_(per_report), steps_(start) {}
  std::string_view algorithm() const override { return "counting"; }
  void learn(long total_steps, const learn::ProgressFn& on_progress) override {
    ++calls;
    while (steps_ < total_steps) {
      steps_ += per_report_;
      if (!on_progress({.steps = steps_}) || per_report_ == 0) break;
    }
  }
  long steps() const override { return steps_; }
  void save(const std::filesystem::path&) const override {}
  void load(const std::filesystem::path&) override {}
  void act(const envs::ObservationBuffers&, std::span<double>, bool) override {}
  std::string config_text() const override { return ""; }
  int calls = 0;

 private:
  long per_report_, steps_;
};

TEST(RunLoop, StopsAtEveryBoundaryButTheLast) {
  CountingLearner learner(100);
  std::vector<long> boundaries, reports;
  const long next =
      run_loop(learner, {.total_steps = 1000,
                         .boundary_every = 300,
                         .report =
                             [&](const learn::TrainStats& s) {
                               reports.push_back(s.steps);
                               return true;
                             },
                         .at_boundary = [&] { boundaries.push_back(learner.steps()); }});
  EXPECT_EQ(learner.steps(), 1000);
  EXPECT_EQ(boundaries, (std::vector<long>{300, 600, 900}));
  EXPECT_EQ(learner.calls, 4);
  EXPECT_EQ(reports.size(), 10u);
  // The last interval (900 -> 1000) crossed no boundary: the next one is 1200.
  EXPECT_EQ(next, 1200);
}

TEST(RunLoop, BoundariesAreMultiplesFromAResumedStepAndOvershootIsAllowed) {
  CountingLearner learner(250, /*start=*/500);
  std::vector<long> boundaries;
  const long next =
      run_loop(learner, {.total_steps = 2000, .boundary_every = 600, .at_boundary = [&] {
                           boundaries.push_back(learner.steps());
                         }});
  // Reports at 750, 1000, ...: the first at or past 600 is 750, at or past 1200 is 1250; the
  // run ends at 2000, past 1800, which it does not act on (the caller's final checkpoint does).
  EXPECT_EQ(boundaries, (std::vector<long>{750, 1250}));
  EXPECT_EQ(learner.steps(), 2000);
  EXPECT_EQ(next, 1800);
}

TEST(RunLoop, WithoutBoundariesOneLearnCall) {
  CountingLearner learner(64);
  int boundaries = 0;
  const long next = run_loop(learner, {.total_steps = 640, .at_boundary = [&] { ++boundaries; }});
  EXPECT_EQ(learner.calls, 1);
  EXPECT_EQ(boundaries, 0);
  EXPECT_EQ(next, -1);
}

TEST(RunLoop, AReportOrTheStopFlagEndsIt) {
  CountingLearner by_report(100);
  run_loop(by_report, {.total_steps = 1000,
                       .boundary_every = 300,
                       .report = [](const learn::TrainStats& s) { return s.steps < 400; }});
  EXPECT_EQ(by_report.steps(), 400);
  EXPECT_EQ(by_report.calls, 2);

  CountingLearner by_flag(100);
  bool stop = false;
  run_loop(by_flag, {.total_steps = 1000,
                     .report =
                         [&](const learn::TrainStats& s) {
                           stop = s.steps >= 200;
                           return true;
                         },
                     .stopping = [&] { return stop; }});
  EXPECT_EQ(by_flag.steps(), 200);
}

TEST(RunLoop, ALearnerThatCannotAdvanceEndsIt) {
  CountingLearner stuck(0);
  run_loop(stuck, {.total_steps = 1000, .boundary_every = 100});
  EXPECT_EQ(stuck.steps(), 0);
  EXPECT_EQ(stuck.calls, 1);
}

TEST(Loop, CsvCellsAndDurations) {
  EXPECT_EQ(csv_cell(std::nan("")), "");
  EXPECT_EQ(csv_cell(0.1234567), "0.123457");
  EXPECT_EQ(csv_cell(1536), "1536");
  EXPECT_EQ(duration_text(3723), "1:02:03");
  EXPECT_EQ(duration_text(-1), "--:--");
}

}  // namespace
}  // namespace cradle::train

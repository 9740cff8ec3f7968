// `cradle soak` on an env id in worker processes: it runs to the end with its evaluations beside
// the live vector, reports steps/s and each worker's resident memory, and refuses a wrong choice
// of env in one line.
#include <gtest/gtest.h>

#include <regex>
#include <string>
#include <vector>

#include "fixture.h"

namespace {

using cradle::test::fresh_dir;
using cradle::test::run_cradle;

TEST(Soak, AnEnvIdInWorkerProcessesReportsEachWorkersMemory) {
  const std::filesystem::path dir = fresh_dir("soak_id");
  const cradle::test::RunResult r = run_cradle(
      "soak --env mimo/reach --envs 2 --procs 2 --steps 10000 --eval-every 6000 "
      "--eval-duration 20 --out '" +
      dir.string() + "'");
  ASSERT_EQ(r.status, 0) << r.out;
  // One progress line at 10,000 steps, with the parent's and both workers' resident memory.
  EXPECT_TRUE(std::regex_search(
      r.out, std::regex("10000 steps, [0-9]+ steps/s, RSS [0-9]+ MB \\(peak [0-9]+ MB\\), workers "
                        "[1-9][0-9]* [1-9][0-9]* MB\n")))
      << r.out;
  EXPECT_NE(r.out.find("evaluation 1 (beside the vector): 1 episodes, mean return"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("soak finished: 10000 env steps on 2 envs in 2 processes, 2 evaluations, "),
            std::string::npos)
      << r.out;
  // The same line in soak.csv, for the memory curve.
  const std::vector<std::string> table = cradle::test::read_lines(dir / "soak.csv");
  ASSERT_EQ(table.size(), 2u);
  EXPECT_EQ(table[0],
            "steps,seconds,steps_per_s,rss_mb,peak_rss_mb,worker_0_rss_mb,worker_1_rss_mb");
  EXPECT_TRUE(std::regex_match(table[1], std::regex("10000(,[0-9.e+]+){6}"))) << table[1];
}

TEST(Soak, AWrongEnvChoiceIsOneLine) {
  const std::string out = " --steps 10 --out '" + fresh_dir("soak_refused").string() + "'";
  const cradle::test::RunResult none = run_cradle("soak" + out);
  EXPECT_NE(none.status, 0);
  EXPECT_EQ(none.out,
            "cradle: error: soak: give a BabyBench config (--config FILE) or an env id (--env "
            "ID)\n");
  const cradle::test::RunResult config = run_cradle("soak --env babybench/selftouch" + out);
  EXPECT_NE(config.status, 0);
  EXPECT_EQ(config.out,
            "cradle: error: soak: --env babybench/selftouch is a BabyBench config: give it as "
            "--config\n");
  const cradle::test::RunResult file =
      run_cradle("soak --env mimo/reach --steps 10 --out /etc/hostname");
  EXPECT_NE(file.status, 0);
  EXPECT_EQ(file.out,
            "cradle: error: soak: cannot create the output folder '/etc/hostname': Not a "
            "directory\n");
  const cradle::test::RunResult uneven =
      run_cradle("soak --env mimo/reach --envs 3 --procs 2" + out);
  EXPECT_NE(uneven.status, 0);
  EXPECT_EQ(uneven.out,
            "cradle: error: soak: --envs 3 does not split evenly over --procs 2; give --envs a "
            "multiple of --procs\n");
}

}  // namespace

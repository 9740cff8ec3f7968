// `cradle tma campaign generate|launch` and `cradle tma analyze`: the generated benchmark (lines,
// seeds, offsets, criteria), the local pool and --resume, the sbatch scripts, a real one-node
// Slurm through scripts/slurm-local.sh (skipped with a message where its daemons cannot start),
// and the analysis of the results. Runs use tests/tma_campaign/fake_tma_run.py in place of
// `cradle tma run` (a synthetic run folder in the agreed format, in well under a second).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "campaign_lines.h"
#include "envs/tma/tma_env.h"
#include "fixture.h"
#include "learn/registry.h"
#include "learn/run_files.h"
#include "learn/vector_env.h"

namespace {

namespace fs = std::filesystem;

using cradle::test::run_cradle;
using cradle::test::RunResult;

// A shell command, stdout and stderr together.
RunResult shell(const std::string& cmd) { return cradle::test::run(cmd + " 2>&1"); }

using cradle::test::config_lines;
using cradle::test::count;

fs::path fresh(const std::string& tag) {
  const fs::path d =
      fs::temp_directory_path() / ("cradle_campaign_" + tag + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

const std::string kRunner = std::string("--runner '/usr/bin/python3 ") + CRADLE_SOURCE_DIR +
                            "/tests/tma_campaign/fake_tma_run.py'";

// Two configurations x 2 seeds; the second with a seed offset.
fs::path mini_campaign(const fs::path& dir) {
  const fs::path file = dir / "mini.txt";
  std::ofstream(file)
      << "# Random vs ALP-GMM, criterion 1\n"
      << "--seeds 2 --campaign rnd --experiment criterion_1 --name rnd_c1 --env stump-tracks "
         "--teacher Random --*allow_expert_knowledge none\n"
      << "\n--seeds 2+4 --campaign alp --experiment criterion_1 --name alp_c1 --env stump-tracks "
         "--teacher ALP-GMM --*allow_expert_knowledge none  # trailing comment\n";
  return file;
}

const std::vector<std::string> kSeedDirs = {
    "rnd_c1_allow_expert_knowledge_none/rnd_c1_allow_expert_knowledge_none_s0",
    "rnd_c1_allow_expert_knowledge_none/rnd_c1_allow_expert_knowledge_none_s1",
    "alp_c1_allow_expert_knowledge_none/alp_c1_allow_expert_knowledge_none_s4",
    "alp_c1_allow_expert_knowledge_none/alp_c1_allow_expert_knowledge_none_s5"};

// Every figure and table of the analysis of the mini campaign.
void expect_analysis(const fs::path& results) {
  const RunResult r = run_cradle("tma analyze " + results.string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("4 runs, baseline rnd"), std::string::npos) << r.out;
  for (const char* f : {"curves_criterion_1_none.png", "train_return_criterion_1_none.png",
                        "pairwise_criterion_1_none.png", "skill_radar.png", "skill_bars.png",
                        "curriculum_alp_criterion_1_old_classic_bipedal.png",
                        "testset_rnd_criterion_1_old_classic_bipedal.png", "summary.md",
                        "summary.csv", "welch_tests.csv", "skill_ratios.csv"}) {
    const fs::path p = results / "analysis" / f;
    ASSERT_TRUE(fs::exists(p)) << p;
    EXPECT_GT(fs::file_size(p), 100u) << p;
  }
  std::ifstream md(results / "analysis" / "summary.md");
  const std::string text((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("| criterion_1 | none | alp | 2 |"), std::string::npos) << text;
}

TEST(TmaCampaign, GeneratesBothExperimentsWithTheReferenceSeeds) {
  RunResult r =
      run_cradle("tma campaign generate alp --teacher ALP-GMM --teacher-param fit_rate=150");
  ASSERT_EQ(r.status, 0) << r.out;
  std::vector<std::string> lines = config_lines(r.out);
  // 3 EK x (criteria 1-4 + 4 criterion-5 variants) + 3 Parkour + 3 upper-baseline lines.
  ASSERT_EQ(lines.size(), 30u);
  EXPECT_EQ(count(lines, "--seeds 16 "), 24 + 1);
  EXPECT_EQ(count(lines, "--seeds 16+16 "), 1);
  EXPECT_EQ(count(lines, "--seeds 16+32 "), 1);
  EXPECT_EQ(count(lines, "--seeds 32 "), 3);
  EXPECT_EQ(count(lines, "--teacher ALP-GMM --teacher-param fit_rate=150"), 30);
  EXPECT_EQ(count(lines, "--nb_env_steps 20 --test_every 500000"), 30);
  EXPECT_EQ(count(lines, "--max_stump_h 9 --max_obstacle_spacing 6"), 3);
  EXPECT_EQ(count(lines, "--min_stump_h -3 --max_stump_h 3"), 3);
  EXPECT_EQ(count(lines, "--reset_frequency 7000000"), 3);
  EXPECT_EQ(count(lines, "--shuffle_dimensions"), 3);
  EXPECT_EQ(count(lines, "--experiment criterion_5"), 12);
  EXPECT_EQ(count(lines, "--*student ppo --lr 0.0003"), 6);
  EXPECT_EQ(count(lines, "--*embodiment fish --test_set swimming_test_set_v1"), 1);
  EXPECT_EQ(count(lines, "--*embodiment climbing_profile_chimpanzee"), 1);
  EXPECT_EQ(count(lines, "--*allow_expert_knowledge high"), 9);

  // Random: only the no-EK block (the analysis duplicates it); ADR: no "none", 32 seeds.
  r = run_cradle("tma campaign generate rnd --teacher Random");
  lines = config_lines(r.out);
  EXPECT_EQ(lines.size(), 12u);
  EXPECT_EQ(count(lines, "allow_expert_knowledge low"), 3);  // Parkour is low EK
  r = run_cradle("tma campaign generate adr --teacher ADR");
  lines = config_lines(r.out);
  EXPECT_EQ(lines.size(), 21u);
  EXPECT_EQ(count(lines, "allow_expert_knowledge none"), 0);
  EXPECT_EQ(count(lines, "--seeds 32 "), 14);  // not criterion 5 at high EK, nor Parkour

  // Mini preset and overrides scale the budget and the seeds.
  const fs::path dir = fresh("generate");
  r = run_cradle("tma campaign generate m --teacher Random --preset mini --out " +
                 (dir / "m.txt").string());
  ASSERT_EQ(r.status, 0) << r.out;
  std::ifstream in(dir / "m.txt");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  lines = config_lines(text);
  EXPECT_EQ(count(lines, "--seeds 2 "), 9);
  EXPECT_EQ(count(lines, "--nb_env_steps 0.02 --test_every 10000"), 12);
  EXPECT_EQ(count(lines, "--nb_test_episodes 10 "), 12);
  EXPECT_EQ(count(lines, "--test_set"), 0);
  r = run_cradle("tma campaign generate m --teacher Random --steps 2 --seeds 4");
  lines = config_lines(r.out);
  EXPECT_EQ(count(lines, "--seeds 4+8 "), 1);
  EXPECT_EQ(count(lines, "--nb_env_steps 2 --test_every 50000"), 12);
  EXPECT_EQ(count(lines, "--test_set parametric_stumps_test_set"), 9);
  // The generated file is a valid campaign: the dry run lists every seed.
  r = run_cradle("tma campaign launch " + (dir / "m.txt").string() +
                 " --local --dry-run --results " + (dir / "res").string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(config_lines(r.out).size(), 8u * 2 + 3 * 2 + 1 * 4);
  EXPECT_NE(r.out.find("--exp_name m_parkour_embodiment_fish --seed 5 --out"), std::string::npos)
      << r.out;
  fs::remove_all(dir);
}

TEST(TmaCampaign, BadInputIsOneLineError) {
  const fs::path dir = fresh("bad");
  int files = 0;
  const auto write = [&](const std::string& text) {
    const fs::path file = dir / ("c" + std::to_string(files++) + ".txt");
    std::ofstream(file) << text;
    return file.string();
  };
  const std::vector<std::string> cases = {
      "tma campaign generate x --teacher Random --preset huge",
      "tma campaign generate 'a b' --teacher Random",
      "tma campaign generate x --teacher Random --teacher-param fit_rate",
      "tma campaign launch " + (dir / "missing.txt").string(),
      "tma campaign launch " + write("# nothing\n"),
      "tma campaign launch " + write("--name a --env stump-tracks\n"),
      "tma campaign launch " + write("--seeds 2x --name a\n"),
      "tma campaign launch " + write("--seeds 2 --name a --seed 3\n"),
      "tma campaign launch " + write("--seeds 2 --name a\n--seeds 1 --name a\n"),
      "tma campaign launch " + write("--seeds 2 --name a/b\n"),
      "tma campaign launch " + write("--seeds 1 --name a\n") + " --jobs 0",
      "tma analyze " + (dir / "nothing").string()};
  for (const std::string& args : cases) {
    const RunResult r = run_cradle(args);
    EXPECT_EQ(r.status, 1) << args << "\n" << r.out;
    EXPECT_EQ(r.out.rfind("cradle: error: ", 0), 0u) << args << "\n" << r.out;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << args << "\n" << r.out;
  }
  fs::remove_all(dir);
}

// Input that would be code in a campaign file or an sbatch script (fuzzing's finds): each is exit
// 1 with one line naming what is wrong and what was expected, and nothing is written.
TEST(TmaCampaign, UnsafeOrImplausibleInputIsRefusedAndWritesNothing) {
  const fs::path dir = fresh("unsafe");
  const fs::path out = dir / "out.txt";
  const fs::path results = dir / "res";
  int files = 0;
  const auto write = [&](const std::string& text) {
    const fs::path file = dir / ("c" + std::to_string(files++) + ".txt");
    std::ofstream(file) << text;
    return file.string();
  };
  const std::string gen = "tma campaign generate x --out " + out.string() + " ";
  const std::string ok = " --env stump-tracks --teacher Random --allow_expert_knowledge none\n";
  // A dry run of `text` (local unless `options` say otherwise) into `results`.
  const auto launch = [&](const std::string& text, const std::string& options = "--local",
                          const std::string& into = "") {
    return "tma campaign launch " + write(text) + " --dry-run --results " +
           (into.empty() ? results.string() : into) + " " + options;
  };
  struct Case {
    std::string args, says;  // the command and a piece of its error
  };
  const std::vector<Case> cases = {
      // generate: teachers through the registry, their parameters as the teacher reads them.
      {gen + "--teacher 'ALP-GMM;touch${IFS}X'", "expected one of: Random, ADR, ALP-GMM"},
      {gen + "--teacher NoSuchTeacher", "--teacher 'NoSuchTeacher' (expected one of"},
      {gen + "--teacher ALP-GMM --teacher-param fit_rate=abc", "'fit_rate' is \"abc\""},
      {gen + "--teacher ALP-GMM --teacher-param fit_rate=-3", "fit_rate must be >= 2"},
      {gen + "--teacher ALP-GMM --teacher-param no_such=1", "unknown parameter 'no_such'"},
      {gen + "--teacher ALP-GMM --teacher-param fit_rate=2 --teacher-param fit_rate=3",
       "given twice"},
      {gen + "--teacher ALP-GMM --teacher-param $'fit_rate=150\\ntouch X'", "key=value"},
      {"tma campaign generate . --teacher Random --out " + out.string(), "campaign name '.'"},
      {"tma campaign generate .. --teacher Random --out " + out.string(), "campaign name '..'"},
      {gen + "--teacher Random --steps nan", "--steps nan (expected millions"},
      {gen + "--teacher Random --steps 1e300", "--steps 1e+300 (expected millions"},
      {gen + "--teacher Random --steps -1", "--steps -1 (expected millions"},
      // launch: the file as edited by hand.
      {launch("--seeds 1 --name a --env stump-tracks --teacher ALP-GMM;touch${IFS}X\n"),
       ":1: unknown teacher"},
      {launch("--seeds 1 --name a --teacher NoSuchTeacher\n"), "unknown teacher 'NoSuchTeacher'"},
      {launch("--seeds 1 --name a --teacher ALP-GMM --teacher-param fit_rate=abc\n"),
       ":1: ALP-GMM: parameter 'fit_rate'"},
      {launch("--seeds 1 --name a --teacher=ALP-GMM --teacher-param=fit_rate=abc\n"),
       "parameter 'fit_rate'"},
      {launch("--seeds 1 --name a --teacher ADR --allow_expert_knowledge none\n"),
       "expert knowledge none"},
      {launch("--seeds 1 --name ." + ok), "--name '.'"},
      {launch("--seeds 1 --name .." + ok), "--name '..'"},
      {launch("--seeds 1 --name -a" + ok), "--name"},
      {launch("--seeds 1 --name a --name .." + ok), "--name is given twice"},
      {launch("# ok\n--seeds 1 --name a" + ok + "--seeds 1 --name b --env stump-tracks --*env\n"),
       ":3: --*env needs a value"},
      {launch("--seeds 2000000000 --name a" + ok), ":1: --seeds '2000000000'"},
      {launch("--seeds 99999999999999999999 --name a" + ok), "--seeds"},
      {launch("--seeds 2+2000000000 --name a" + ok), "--seeds offset"},
      {launch("--seeds 1 --name a --nb_env_steps nan" + ok), "--nb_env_steps nan"},
      {launch("--seeds 1 --name a --nb_env_steps 1e300" + ok), "--nb_env_steps 1e+300"},
      {launch(std::string("--seeds 1 --name a\x01") + "b" + ok), "control character"},
      {launch(std::string("--seeds 1 --name a --env x\0;touch X", 35) + ok), "x\\x00;touch X"},
      {launch("--seeds 1 --name a" + ok, "--local --jobs 100000"), "--jobs 100000"},
      // Options that reach the sbatch script or a command line.
      {launch("--seeds 1 --name a" + ok, "--slurm --sbatch $'--time=1:00:00\\ntouch X'"),
       "--sbatch '--time=1:00:00\\x0atouch X'"},
      {launch("--seeds 1 --name a" + ok, "--slurm --sbatch 'x; touch X'"), "--sbatch"},
      {launch("--seeds 1 --name a" + ok, "--slurm", "$'r\\nx'"), "--results 'r\\x0ax'"},
      {launch("--seeds 1 --name a" + ok, "--local --runner $'python3\\ntouch X'"), "--runner"},
  };
  for (const Case& c : cases) {
    // bash, for the $'...' words.
    const RunResult r = cradle::test::run("cd " + dir.string() + " && bash -c " + [&] {
      std::string q = "'";
      for (const char ch : std::string(CRADLE_BINARY) + " " + c.args + " 2>&1")
        q += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
      return q + "'";
    }());
    EXPECT_EQ(r.status, 1) << c.args << "\n" << r.out;
    EXPECT_EQ(r.out.rfind("cradle: error: ", 0), 0u) << c.args << "\n" << r.out;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << c.args << "\n" << r.out;
    EXPECT_NE(r.out.find(c.says), std::string::npos) << c.args << "\n" << r.out;
    EXPECT_FALSE(fs::exists(out)) << c.args;
    EXPECT_FALSE(fs::exists(results)) << c.args;
    EXPECT_FALSE(fs::exists(dir / "X")) << c.args;
  }
  // The limits themselves are fine; a valid --teacher-param still passes.
  RunResult r = run_cradle(launch("--seeds 100000+999900001 --name a" + ok, "--slurm"));
  EXPECT_EQ(r.status, 0) << r.out.substr(0, 300);
  r = run_cradle(gen + "--teacher ALP-GMM --teacher-param fit_rate=150 " +
                 "--teacher-param potential_ks=[2,4] --steps 0.5");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(fs::exists(out));
  r = run_cradle("tma campaign launch " + out.string() + " --slurm --dry-run --results " +
                 results.string() + " --sbatch --time=20:00:00");
  ASSERT_EQ(r.status, 0) << r.out.substr(0, 300);
  EXPECT_NE(r.out.find("--teacher-param 'potential_ks=[2,4]'"), std::string::npos);
  EXPECT_FALSE(fs::exists(results));
  // A hand-edited line with shell characters in a run argument is quoted in the script.
  r = run_cradle(launch("--seeds 1 --name a --env stump;touch${IFS}X" + ok,
                        "--slurm --sbatch --time=1:00:00"));
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("--env 'stump;touch${IFS}X'"), std::string::npos) << r.out;
  fs::remove_all(dir);
}

TEST(TmaCampaign, LocalPoolRunsEverySeedResumesAndAnalyses) {
  const fs::path dir = fresh("local");
  const fs::path file = mini_campaign(dir);
  const fs::path results = dir / "results";
  const std::string launch = "tma campaign launch " + file.string() +
                             " --local --jobs 2 --results " + results.string() + " " + kRunner;
  RunResult r = run_cradle(launch);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("4 runs finished"), std::string::npos) << r.out;
  for (const std::string& d : kSeedDirs) {
    EXPECT_TRUE(fs::exists(results / d / "finished")) << d;
    EXPECT_TRUE(fs::exists(results / d / "progress.csv")) << d;
  }
  // launch.json: what ran, with which seed and where.
  std::ifstream in(results / kSeedDirs[3] / "launch.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["seed"], 5);
  EXPECT_EQ(j["campaign"], "alp");
  EXPECT_EQ(j["experiment"], "criterion_1");
  EXPECT_EQ(j["campaign_line"], 4);  // after a comment and a blank line
  const std::vector<std::string> cmd = j["command"];
  ASSERT_GE(cmd.size(), 6u);
  EXPECT_EQ(cmd[cmd.size() - 3], "5");
  EXPECT_EQ(cmd.back(), (results / kSeedDirs[3]).string());

  // A second launch refuses to overwrite; --resume runs only the unfinished seed, resumed.
  r = run_cradle(launch);
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("use --resume"), std::string::npos) << r.out;
  fs::remove(results / kSeedDirs[1] / "finished");
  r = run_cradle(launch + " --resume");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("3 finished seeds skipped"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("1 runs finished"), std::string::npos) << r.out;
  std::ifstream log(results / kSeedDirs[1] / "log.txt");
  const std::string text((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("seed 1 (resumed)"), std::string::npos) << text;

  // A failing run: exit 1, named, and its seed left unfinished for the next --resume.
  fs::remove(results / kSeedDirs[2] / "finished");
  r = shell("CRADLE_FAKE_FAIL_SEED=4 " + std::string(CRADLE_BINARY) + " " + launch + " --resume");
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("alp_c1_allow_expert_knowledge_none seed 4 (exit 3"), std::string::npos)
      << r.out;
  EXPECT_FALSE(fs::exists(results / kSeedDirs[2] / "finished"));
  ASSERT_EQ(run_cradle(launch + " --resume").status, 0);

  expect_analysis(results);
  fs::remove_all(dir);
}

TEST(TmaCampaign, DryRunPrintsOneArrayPerLineWithPinnedSeeds) {
  const fs::path dir = fresh("dry");
  std::ofstream(dir / "c.txt") << "--seeds 16+16 --name climb --env parkour --teacher Random\n"
                               << "--seeds 3 --name small --env stump-tracks --teacher Random\n";
  const std::string launch = "tma campaign launch " + (dir / "c.txt").string() +
                             " --slurm --dry-run --sbatch --time=20:00:00 --results " +
                             (dir / "res").string() + " " + kRunner;
  RunResult r = run_cradle(launch);
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("#SBATCH --array=0-1\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("#SBATCH --array=0\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("#SBATCH --cpus-per-task=8\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("#SBATCH --cpus-per-task=3\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("#SBATCH --time=20:00:00\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("first=$((16 + SLURM_ARRAY_TASK_ID * 8))"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("taskset -c \"$cpu\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("--exp_name climb --seed \"$seed\" --out \"$dir\" $resume"),
            std::string::npos)
      << r.out;
  EXPECT_FALSE(fs::exists(dir / "res"));  // a dry run writes nothing
  // --resume: only the array tasks that still hold an unfinished seed.
  for (int s = 16; s < 24; ++s) {
    const fs::path d = dir / "res" / "climb" / ("climb_s" + std::to_string(s));
    fs::create_directories(d);
    std::ofstream(d / "finished") << "{}\n";
  }
  r = run_cradle(launch + " --resume");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("8 finished seeds skipped"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("#SBATCH --array=1\n"), std::string::npos) << r.out;
  fs::remove_all(dir);
}

// The issue's integration test: a 2-run x 2-seed campaign through a real one-node Slurm.
TEST(TmaCampaign, SlurmRunsTheMiniCampaign) {
  const std::string script = std::string(CRADLE_SOURCE_DIR) + "/scripts/slurm-local.sh";
  const std::string conf = "SLURM_CONF=/tmp/cradle-slurm/slurm.conf ";
  const bool was_up = shell(conf + "sinfo -h").status == 0;
  const RunResult up = shell(script + " start");
  if (up.status != 0) {
    GTEST_SKIP() << "a one-node Slurm cannot start here (" << up.out
                 << "); the local-pool test covers the launcher";
  }
  const fs::path dir = fresh("slurm");
  const fs::path results = dir / "results";
  const RunResult r =
      shell(conf + CRADLE_BINARY + " tma campaign launch " + mini_campaign(dir).string() +
            " --slurm --wait --seeds-per-job 2 --results " + results.string() + " " + kRunner);
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("4 of 4 runs finished"), std::string::npos) << r.out;
  for (const std::string& d : kSeedDirs) EXPECT_TRUE(fs::exists(results / d / "finished")) << d;
  EXPECT_TRUE(fs::exists(results / "alp_c1_allow_expert_knowledge_none" / "launch" /
                         "alp_c1_allow_expert_knowledge_none.sbatch"));
  EXPECT_TRUE(fs::exists(results / "alp_c1_allow_expert_knowledge_none" / "launch" / "commit.txt"));
  if (r.status == 0) expect_analysis(results);
  if (!was_up) shell(script + " stop");
  fs::remove_all(dir);
}

// The generated lines run with the real `cradle tma run` (a tiny budget: random actions, 3 test
// tasks) and the analysis reads its run folders: Random vs ALP-GMM on criterion 1, 2 seeds each.
TEST(TmaCampaign, RealRunsOfGeneratedLinesAreAnalysed) {
  const fs::path dir = fresh("real");
  std::string lines;
  for (const char* teacher : {"Random", "ALP-GMM"}) {
    const RunResult r = run_cradle(std::string("tma campaign generate ") + teacher + " --teacher " +
                                   teacher + " --preset mini --steps 0.002 --test-episodes 4");
    ASSERT_EQ(r.status, 0) << r.out;
    for (const std::string& l : config_lines(r.out)) {
      if (l.find("--experiment criterion_1 ") != std::string::npos &&
          l.find("knowledge none") != std::string::npos) {
        lines += l + "\n";
      }
    }
  }
  std::ofstream(dir / "c.txt") << lines;
  const fs::path results = dir / "results";
  RunResult r = run_cradle("tma campaign launch " + (dir / "c.txt").string() +
                           " --local --jobs 2 --results " + results.string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("4 runs finished"), std::string::npos) << r.out;
  const fs::path run = results / "ALP-GMM_criterion_1_allow_expert_knowledge_none" /
                       "ALP-GMM_criterion_1_allow_expert_knowledge_none_s1";
  for (const char* f : {"run.json", "progress.csv", "test_returns.csv", "test_set.csv",
                        "logs/teacher.jsonl", "launch.json", "finished"}) {
    EXPECT_TRUE(fs::exists(run / f)) << f;
  }
  std::ifstream in(run / "run.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["arguments"]["seed"], 1);
  EXPECT_EQ(j["arguments"]["max_stump_h"], 9.0);
  // --resume: a seed whose marker is gone is finished by its summary.json (the run not stopped);
  // one whose run was stopped runs on.
  fs::remove(run / "finished");
  const fs::path other = results / "Random_criterion_1_allow_expert_knowledge_none" /
                         "Random_criterion_1_allow_expert_knowledge_none_s0";
  fs::remove(other / "finished");
  std::string summary;
  {
    std::ifstream in(other / "summary.json");
    summary.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  ASSERT_NE(summary.find("\"stopped\": false"), std::string::npos) << summary;
  summary.replace(summary.find("\"stopped\": false"), 17, "\"stopped\": true");
  std::ofstream(other / "summary.json", std::ios::trunc) << summary;
  r = run_cradle("tma campaign launch " + (dir / "c.txt").string() +
                 " --local --resume --results " + results.string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("--resume: 3 finished seeds skipped"), std::string::npos) << r.out;
  EXPECT_NE(cradle::test::read_lines(run / "finished").front().find("summary.json"),
            std::string::npos);
  r = run_cradle("tma analyze " + results.string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("4 runs, baseline Random"), std::string::npos) << r.out;
  EXPECT_TRUE(fs::exists(results / "analysis" / "curves_criterion_1_none.png"));
  EXPECT_TRUE(
      fs::exists(results / "analysis" / "curriculum_ALP-GMM_criterion_1_old_classic_bipedal.png"));
  fs::remove_all(dir);
}

// `cradle tma video`: a run folder whose checkpoint is an (untrained) SAC student, as `cradle tma
// run` saves it, renders test task 1 to a video; bad folders and tasks are one-line errors.
TEST(TmaCampaign, VideoRendersTheCheckpointOnATestTask) {
  const fs::path dir = fresh("video");
  std::ofstream(dir / "run.json")
      << R"({"arguments": {"env": "stump-tracks", "embodiment": "old_classic_bipedal"}})";
  std::ofstream(dir / "test_set.csv") << "task_index,stump_height,obstacle_spacing\n"
                                      << "0,0.5,3\n1,0,6\n";
  {
    const cradle::tma::TmaOptions options{.env = cradle::tma::EnvId::kStumpTracks,
                                          .body = "old_classic_bipedal"};
    cradle::learn::ThreadedVecEnv vec(
        1, [&](int) { return std::make_unique<cradle::envs::TmaEnvAdapter>(options); }, 1);
    cradle::learn::LearnerOptions lo;
    lo.hyperparameters = {{"buffer_size", "500"}, {"pi_layers", "32,32"}, {"qf_layers", "32,32"}};
    const auto learner = cradle::learn::make_learner("sac", vec, lo);
    fs::create_directories(dir / "checkpoints");
    cradle::learn::save_run_checkpoint(dir / "checkpoints" / "latest.ckpt", *learner, nullptr, {});
  }
  const fs::path out = dir / "task1.mp4";
  RunResult r = run_cradle("tma video --run " + dir.string() + " --test-task 1 --steps 40 --out " +
                           out.string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("test task 1: return"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("after 0 training steps"), std::string::npos) << r.out;
  EXPECT_GT(fs::file_size(out), 1000u);
  for (const std::string& args :
       {"tma video --run " + dir.string() + " --test-task 2",
        "tma video --run " + (dir / "none").string() + " --test-task 0"}) {
    r = run_cradle(args);
    EXPECT_EQ(r.status, 1) << args << "\n" << r.out;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
  }
  fs::remove_all(dir);
}

}  // namespace

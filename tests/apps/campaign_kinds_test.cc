// `cradle campaign generate|launch|analyze` for every kind of run: the SaMI and BabyBench presets
// (lines from the env and intrinsic-reward registries), the commands the launcher builds for
// `--run sami` and `--run train` lines (quoted, with the launcher's own flags per kind), a tiny
// local SaMI campaign and a tiny BabyBench campaign followed by their tables, --resume from what
// the runs leave behind, and one-line errors that write nothing.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "campaign_lines.h"
#include "envs/registry.h"
#include "fixture.h"
#include "learn/intrinsic/reward.h"

namespace {

namespace fs = std::filesystem;

using cradle::test::run_cradle;
using cradle::test::RunResult;

using cradle::test::config_lines;
using cradle::test::count;

std::string read(const fs::path& file) {
  std::ifstream in(file);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string self_touch() { return cradle::test::config_path("config_selftouch.yml").string(); }

// The SaMI envs as the registry lists them.
std::vector<std::string> sami_envs() {
  std::vector<std::string> names;
  for (const auto& s : cradle::envs::env_specs()) {
    if (s.family != "sami") continue;
    const std::string env = s.id.substr(5, s.id.find(':') - 5);
    if (std::find(names.begin(), names.end(), env) == names.end()) names.push_back(env);
  }
  return names;
}

TEST(CampaignKinds, GeneratesEachKindFromTheRegistries) {
  // SaMI: the paper's four methods on every SaMI env of the registry, 5 seeds, three splits.
  RunResult r = run_cradle("campaign generate paper --kind sami");
  ASSERT_EQ(r.status, 0) << r.out;
  std::vector<std::string> lines = config_lines(r.out);
  const std::vector<std::string> envs = sami_envs();
  ASSERT_FALSE(envs.empty());
  EXPECT_EQ(lines.size(), 4 * envs.size());
  EXPECT_EQ(count(lines, "--run sami --seeds 5 --campaign paper "), static_cast<int>(lines.size()));
  for (const char* m : {"TESAC", "CCM", "SaTESAC", "SaCCM"}) {
    EXPECT_EQ(count(lines, std::string(" --method ") + m + " "), static_cast<int>(envs.size()));
  }
  for (const std::string& e : envs) EXPECT_EQ(count(lines, " --env " + e + " "), 4) << e;
  EXPECT_EQ(count(lines, "--eval train,moderate,extreme --eval-episodes 10"),
            static_cast<int>(lines.size()));
  EXPECT_EQ(count(lines, "--steps-per-env"), 0);  // each env's own budget

  r = run_cradle(
      "campaign generate s --kind sami --envs HalfCheetah,CrippleAnt --methods CCM,SaCCM "
      "--seeds 3 --steps 1000 --eval-episodes 2");
  ASSERT_EQ(r.status, 0) << r.out;
  lines = config_lines(r.out);
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_EQ(lines[0],
            "--run sami --seeds 3 --campaign s --experiment HalfCheetah --name s_HalfCheetah_CCM "
            "--env HalfCheetah --method CCM --steps-per-env 1000 --eval train,moderate,extreme "
            "--eval-episodes 2");
  EXPECT_EQ(count(lines, "--name s_CrippleAnt_SaCCM "), 1);

  // BabyBench: none plus every registered reward the self-touch env can feed; the others are
  // listed as left out with the reason.
  r = run_cradle("campaign generate bb --kind babybench --config " + self_touch() +
                 " --seeds 2 --steps 5000 --algo ppo");
  ASSERT_EQ(r.status, 0) << r.out;
  lines = config_lines(r.out);
  const std::vector<std::string> names = cradle::learn::intrinsic::intrinsic_names();
  int left_out = 0;
  for (const std::string& n : names) {
    const bool line = count(lines, "--name bb_" + n + " ") == 1;
    const bool comment = r.out.find("# " + n + " left out: ") != std::string::npos;
    EXPECT_NE(line, comment) << n << "\n" << r.out;
    left_out += comment;
  }
  EXPECT_EQ(lines.size(), names.size() + 1 - left_out);
  EXPECT_NE(r.out.find("# saliency left out: "), std::string::npos) << r.out;  // no vision
  EXPECT_EQ(count(lines, "--intrinsic touch_count"), 1);
  EXPECT_EQ(count(lines, "--name bb_none --config " + self_touch() +
                             " --algo ppo --steps 5000 --no-eval-video --intrinsic ''"),
            1);
  EXPECT_EQ(count(lines, "--run train --seeds 2 --campaign bb --experiment self_touch "),
            static_cast<int>(lines.size()));

  // tma: today's `tma campaign generate`, word for word.
  const RunResult a = run_cradle("campaign generate m --kind tma --teacher Random --preset mini");
  const RunResult b = run_cradle("tma campaign generate m --teacher Random --preset mini");
  ASSERT_EQ(a.status, 0) << a.out;
  EXPECT_EQ(a.out, b.out);
}

// A campaign file mixing the kinds, with an empty argument and words a shell would read.
fs::path mixed_campaign(const fs::path& dir) {
  const fs::path file = dir / "mixed.txt";
  std::ofstream(file) << "# one line of each kind\n"
                      << "--run sami --seeds 2 --name s --env HalfCheetah --method SaCCM "
                         "--steps-per-env 300 --hp note=$HOME;x --eval train,extreme "
                         "--eval-episodes 1\n"
                      << "--run train --seeds 1+3 --name b --config " << self_touch()
                      << " --intrinsic '' --steps 256 --*envs 1\n"
                      << "--seeds 1 --name t --env stump-tracks --teacher Random\n";
  return file;
}

TEST(CampaignKinds, DryRunPrintsEachKindsCommandsQuoted) {
  const fs::path dir = cradle::test::fresh_dir("campaign_dry");
  const fs::path file = mixed_campaign(dir);
  const fs::path results = dir / "res";
  RunResult r = run_cradle("campaign launch " + file.string() + " --local --dry-run --results " +
                           results.string());
  ASSERT_EQ(r.status, 0) << r.out;
  const std::vector<std::string> lines = config_lines(r.out);
  ASSERT_EQ(lines.size(), 4u) << r.out;
  const std::string exe = fs::canonical(CRADLE_BINARY).string();
  const std::string s0 = (results / "s" / "s_s0").string();
  EXPECT_EQ(lines[0], exe +
                          " sami train --env HalfCheetah --method SaCCM --steps-per-env 300 --hp "
                          "'note=$HOME;x' --no-progress --seed 0 --out " +
                          s0 + " && " + exe + " sami evaluate --run " + s0 +
                          " --split train --episodes 1 && " + exe + " sami evaluate --run " + s0 +
                          " --split extreme --episodes 1");
  EXPECT_EQ(lines[2], exe + " train --config " + self_touch() +
                          " --intrinsic '' --steps 256 --envs 1 --seed 3 --save-dir " +
                          (results / "b_envs_1" / "b_envs_1_s3").string());
  EXPECT_EQ(lines[3], exe +
                          " tma run --env stump-tracks --teacher Random --exp_name t --seed 0 "
                          "--out " +
                          (results / "t" / "t_s0").string());
  EXPECT_FALSE(fs::exists(results));

  // The sbatch scripts: each kind's folder flag, resume rule and (SaMI) evaluations.
  r = run_cradle("campaign launch " + file.string() + " --slurm --dry-run --results " +
                 results.string());
  ASSERT_EQ(r.status, 0) << r.out;
  for (const char* expected :
       {"--no-progress --seed \"$seed\" --out \"$dir\" $resume",
        "sami evaluate --run \"$dir\" --split extreme --episodes 1 >> \"$dir/log.txt\"",
        "[ -e \"$dir/checkpoints/latest.ckpt\" ] && resume=--resume",
        "--intrinsic '' --steps 256 --envs 1 --seed \"$seed\" --save-dir \"$dir\" $resume",
        "elif [ -e \"$dir/logs/progress.csv\" ]; then resume=--overwrite; fi",
        "--exp_name t --seed \"$seed\" --out \"$dir\" $resume",
        "(cradle campaign launch, --run "
        "train)"}) {
    EXPECT_NE(r.out.find(expected), std::string::npos) << expected << "\n" << r.out;
  }
  EXPECT_FALSE(fs::exists(results));
  fs::remove_all(dir);
}

// A tiny SaMI campaign (two methods, one seed, a few hundred steps per env) and a tiny BabyBench
// campaign (no intrinsic reward vs touch_count, one seed, one rollout) through the local pool,
// then their tables.
TEST(CampaignKinds, TinySamiAndBabyBenchCampaignsRunAndAnalyze) {
  const fs::path dir = cradle::test::fresh_dir("campaign_tiny");
  const fs::path file = dir / "tiny.txt";
  const fs::path results = dir / "res";
  RunResult r = run_cradle(
      "campaign generate s --kind sami --envs HalfCheetah --methods "
      "TESAC,SaCCM --seeds 1 --steps 200 --eval-episodes 1 --out " +
      (dir / "s.txt").string());
  ASSERT_EQ(r.status, 0) << r.out;
  r = run_cradle("campaign generate b --kind babybench --config " + self_touch() +
                 " --intrinsics none,touch_count --seeds 1 --steps 128 --out " +
                 (dir / "b.txt").string());
  ASSERT_EQ(r.status, 0) << r.out;
  {
    // One split evaluated (the test's budget) and one env per BabyBench run.
    std::string text = read(dir / "s.txt") + read(dir / "b.txt");
    for (size_t at; (at = text.find("train,moderate,extreme")) != std::string::npos;) {
      text.replace(at, 22, "train");
    }
    for (size_t at = 0; (at = text.find("--no-eval-video", at)) != std::string::npos; at += 20) {
      text.replace(at, 15, "--no-eval-video --envs 1 --eval-episodes 1");
    }
    std::ofstream(file) << text;
  }
  r = run_cradle("campaign launch " + file.string() + " --local --jobs 2 --results " +
                 results.string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("4 runs finished"), std::string::npos) << r.out;
  const fs::path sami0 = results / "s_HalfCheetah_SaCCM" / "s_HalfCheetah_SaCCM_s0";
  const fs::path train0 = results / "b_touch_count" / "b_touch_count_s0";
  for (const fs::path& p :
       {sami0 / "eval_train.json", sami0 / "finished", sami0 / "launch.json",
        train0 / "checkpoints" / "final.ckpt", train0 / "evaluation.json", train0 / "finished"}) {
    EXPECT_TRUE(fs::exists(p)) << p;
  }
  EXPECT_NE(read(train0 / "launch.json").find("\"run\": \"train\""), std::string::npos);

  r = run_cradle("campaign analyze " + results.string());
  ASSERT_EQ(r.status, 0) << r.out;
  const std::string sami_table = read(results / "analysis" / "sami_table_s.md");
  EXPECT_NE(sami_table.find("## HalfCheetah (mean return"), std::string::npos) << sami_table;
  EXPECT_NE(sami_table.find("| TESAC | 1 |"), std::string::npos) << sami_table;
  EXPECT_NE(sami_table.find("| SaCCM | 1 |"), std::string::npos) << sami_table;
  const std::string md = read(results / "analysis" / "train_table.md");
  EXPECT_NE(md.find("| b_none | config_selftouch.yml | none | 1 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| b_touch_count | config_selftouch.yml | touch_count | 1 |"),
            std::string::npos)
      << md;
  const std::vector<std::string> csv =
      cradle::test::read_lines(results / "analysis" / "train_table.csv");
  ASSERT_EQ(csv.size(), 3u);
  EXPECT_EQ(csv[0].rfind("campaign,experiment,source,intrinsic,seeds,steps,", 0), 0u);
  EXPECT_EQ(csv[2].rfind("b,b_touch_count,config_selftouch.yml,touch_count,1,", 0), 0u) << csv[2];

  // --resume: every seed is finished; one whose marker is gone is still finished by its files
  // (final.ckpt at the asked steps; SaMI's whole budget and its evaluations), and gets it back.
  fs::remove(train0 / "finished");
  fs::remove(sami0 / "finished");
  r = run_cradle("campaign launch " + file.string() + " --local --resume --results " +
                 results.string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("--resume: 4 finished seeds skipped"), std::string::npos) << r.out;
  EXPECT_NE(read(train0 / "finished").find("checkpoints/final.ckpt"), std::string::npos);
  EXPECT_NE(read(sami0 / "finished").find("checkpoints/final.ckpt"), std::string::npos);
  fs::remove_all(dir);
}

// Every wrong input: exit 1, one line (naming FILE:LINE for a campaign file), nothing written.
TEST(CampaignKinds, WrongInputIsOneLineErrorAndWritesNothing) {
  const fs::path dir = cradle::test::fresh_dir("campaign_bad");
  const fs::path results = dir / "res";
  const fs::path out = dir / "out.txt";
  int files = 0;
  const auto write = [&](const std::string& text) {
    const fs::path file = dir / ("c" + std::to_string(files++) + ".txt");
    std::ofstream(file) << "# a comment first\n" << text;
    return file.string();
  };
  const std::string launch = "campaign launch --local --results " + results.string() + " ";
  const std::string train = "--run train --seeds 1 --name b --config " + self_touch() + " ";
  const std::string sami = "--run sami --seeds 1 --name s --env Hopper ";
  // {arguments, what the line must name}
  const std::vector<std::pair<std::string, std::string>> cases = {
      {launch + write("--run bogus --seeds 1 --name a\n"), ":2: --run 'bogus'"},
      {launch + write(train + "--save-dir x\n"), ":2: --save-dir is set by the launcher"},
      {launch + write(train + "--overwrite\n"), ":2: --overwrite is set by the launcher"},
      {launch + write(train + "--out x\n"), ":2: --out is set by the launcher"},
      {launch + write(sami + "--overwrite\n"), ":2: --overwrite is set by the launcher"},
      {launch + write("--seeds 1 --name t --overwrite\n"), ":2: --overwrite is set by"},
      {launch + write(sami + "--out x\n"), ":2: --out is set by the launcher"},
      {launch + write(sami + "--resume\n"), ":2: --resume is set by the launcher"},
      {launch + write("--seeds 1 --name t --exp_name x\n"), ":2: --exp_name is set by"},
      {launch + write(sami + "--method SaBogus\n"), ":2: "},
      {launch + write("--run sami --seeds 1 --name s --env Mars\n"), ":2: --env 'Mars'"},
      {launch + write(sami + "--eval train,sideways\n"), ":2: --eval 'train,sideways'"},
      {launch + write(sami + "--eval train --eval train\n"), ":2: --eval is given twice"},
      {launch + write(sami + "--steps-per-env 0\n"), ":2: --steps-per-env '0'"},
      {launch + write(train + "--eval train\n"), ":2: --eval is for --run sami lines"},
      {launch + write(train + "--intrinsic bogus\n"), ":2: "},
      {launch + write(train + "--algo bogus\n"), ":2: --algo 'bogus'"},
      {launch + write(train + "--distributed\n"), ":2: --distributed is not for a campaign"},
      {launch + write("--run train --seeds 1 --name b\n"), ":2: --run train needs --config"},
      {launch + write("--run train --seeds 1 --name b --config /no/such.yml\n"), ":2: --config"},
      {launch + write("--run sami --seeds 1 --name s --run train\n"), ":2: --run is given twice"},
      {"campaign generate x --kind bogus --out " + out.string(), "--kind 'bogus'"},
      {"campaign generate x --kind sami --teacher Random --out " + out.string(),
       "--teacher is for --kind tma"},
      {"campaign generate x --kind sami --methods TESAC,Nope --out " + out.string(), "'Nope'"},
      {"campaign generate x --kind sami --envs Mars --out " + out.string(), "--envs: 'Mars'"},
      {"campaign generate x --kind sami --steps 0.5 --out " + out.string(), "--steps 0.5"},
      {"campaign generate x --kind babybench --out " + out.string(), "needs --config"},
      {"campaign generate x --kind babybench --config /no/such.yml --out " + out.string(),
       "is not a file"},
      {"campaign generate x --kind babybench --config " + self_touch() +
           " --intrinsics saliency --out " + out.string(),
       "saliency does not fit"},
      {"campaign generate x --kind babybench --config " + self_touch() +
           " --intrinsics none,bogus --out " + out.string(),
       "'bogus'"},
      {"campaign generate x --kind babybench --config " + self_touch() + " --methods TESAC",
       "--methods is for --kind sami"},
      {"campaign generate x --kind tma --out " + out.string(), "needs --teacher"},
      {"campaign analyze " + (dir / "nothing").string(), "does not exist"},
  };
  for (const auto& [args, needle] : cases) {
    const RunResult r = run_cradle(args);
    EXPECT_EQ(r.status, 1) << args << "\n" << r.out;
    EXPECT_EQ(r.out.rfind("cradle: error: ", 0), 0u) << args << "\n" << r.out;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << args << "\n" << r.out;
    EXPECT_NE(r.out.find(needle), std::string::npos) << args << "\n" << r.out;
    EXPECT_FALSE(fs::exists(results)) << args;
    EXPECT_FALSE(fs::exists(out)) << args;
  }

  // A results tree with a broken launch.json or a torn progress.csv: named, nothing written.
  const fs::path seed = results / "b" / "b_s0";
  fs::create_directories(seed / "logs");
  std::ofstream(seed / "launch.json") << "{\"run\": \"train\", \"name\": \"b\"";
  RunResult r = run_cradle("campaign analyze " + results.string());
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("launch.json is not a JSON object"), std::string::npos) << r.out;
  std::ofstream(seed / "launch.json") << "{\"run\": \"train\", \"name\": \"b\"}";
  std::ofstream(seed / "logs" / "progress.csv") << "global_step,charts/episodic_return\n2048\n";
  r = run_cradle("campaign analyze " + results.string());
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("progress.csv: the last row has 1 cells"), std::string::npos) << r.out;
  EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << r.out;
  EXPECT_FALSE(fs::exists(results / "analysis"));
  fs::remove_all(dir);
}

}  // namespace

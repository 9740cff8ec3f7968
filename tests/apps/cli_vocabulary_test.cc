// The CLI reads as one tool: `cradle --help` says what Cradle is and groups the commands by what
// users do, every --help shows the defaults, and `cradle evaluate` is quick unless asked to film.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "fixture.h"

namespace {

namespace fs = std::filesystem;

using cradle::test::run_cradle;

// The entries under each heading of a --help text ("Envs:" -> {"envs", "random", ...}).
std::map<std::string, std::vector<std::string>> sections(const std::string& help) {
  std::map<std::string, std::vector<std::string>> out;
  std::istringstream in(help);
  std::string heading;
  for (std::string line; std::getline(in, line);) {
    if (!line.empty() && line[0] != ' ' && line.back() == ':') {
      heading = line.substr(0, line.size() - 1);
    } else if (!heading.empty() && line.starts_with("  ") && line[2] != ' ') {
      out[heading].push_back(line.substr(2, line.find(' ', 2) - 2));
    }
  }
  return out;
}

// The line of a --help text that starts with `option` (after the indent).
std::string option_line(const std::string& help, const std::string& option) {
  const size_t at = help.find("\n  " + option);
  if (at == std::string::npos) return "";
  return help.substr(at + 3, help.find('\n', at + 1) - at - 3);
}

std::string read_text(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

// Lines of `out` that start with `prefix`.
int count_lines(const std::string& out, const std::string& prefix) {
  int n = 0;
  std::istringstream in(out);
  for (std::string line; std::getline(in, line);) n += line.starts_with(prefix);
  return n;
}

TEST(CliVocabulary, HelpNamesEveryFamilyAndGroupsTheCommands) {
  const auto r = run_cradle("--help");
  ASSERT_EQ(r.status, 0) << r.out;
  for (const char* family : {"BabyBench", "MIMo", "TeachMyAgent", "SaMI", "`cradle envs`"}) {
    EXPECT_NE(r.out.find(family), std::string::npos) << family << "\n" << r.out;
  }
  const std::map<std::string, std::vector<std::string>> expected = {
      {"Envs", {"envs", "random", "build-scene", "model-info", "test-installation"}},
      {"Train", {"train", "illustrate", "campaign"}},
      {"Evaluate", {"evaluate"}},
      {"Families (reference-compatible commands)", {"tma", "sami"}},
      {"Benchmarks", {"bench", "soak"}},
      {"Distributed", {"launch"}},
  };
  std::map<std::string, std::vector<std::string>> listed = sections(r.out);
  listed.erase("Options");
  EXPECT_EQ(listed, expected) << r.out;
  // The groups come in the order users meet them.
  size_t last = 0;
  for (const char* heading :
       {"\nEnvs:", "\nTrain:", "\nEvaluate:", "\nFamilies", "\nBenchmarks:", "\nDistributed:"}) {
    const size_t at = r.out.find(heading);
    ASSERT_NE(at, std::string::npos) << heading;
    EXPECT_GT(at, last) << heading;
    last = at;
  }
}

TEST(CliVocabulary, EveryHelpShowsTheDefaults) {
  const auto train = run_cradle("train --help");
  ASSERT_EQ(train.status, 0) << train.out;
  EXPECT_NE(option_line(train.out, "--steps ").find("=100000"), std::string::npos) << train.out;
  EXPECT_NE(option_line(train.out, "--algo ").find("=ppo"), std::string::npos) << train.out;
  // A list option shows no empty default, a flag no value.
  EXPECT_EQ(option_line(train.out, "--hp ").find("=[]"), std::string::npos) << train.out;
  EXPECT_EQ(train.out.find("{false}"), std::string::npos) << train.out;

  const auto evaluate = run_cradle("evaluate --help");
  ASSERT_EQ(evaluate.status, 0) << evaluate.out;
  EXPECT_NE(option_line(evaluate.out, "--episodes ").find("=10"), std::string::npos);
  EXPECT_NE(option_line(evaluate.out, "--duration ").find("=1000"), std::string::npos);
  const std::string render = option_line(evaluate.out, "--render,--no-render ");
  EXPECT_NE(render.find("Default: --no-render"), std::string::npos) << evaluate.out;
  EXPECT_NE(render.find("reference"), std::string::npos) << evaluate.out;

  // The families' commands too; a required option shows no default.
  const auto tma = run_cradle("tma run --help");
  ASSERT_EQ(tma.status, 0) << tma.out;
  EXPECT_NE(option_line(tma.out, "--teacher ").find("=ALP-GMM"), std::string::npos) << tma.out;
  const auto sami = run_cradle("sami train --help");
  ASSERT_EQ(sami.status, 0) << sami.out;
  EXPECT_NE(option_line(sami.out, "--method,--algo ").find("=SaCCM"), std::string::npos)
      << sami.out;
  EXPECT_EQ(sami.out.find("{false}"), std::string::npos) << sami.out;  // --no-progress
  const auto video = run_cradle("tma video --help");
  ASSERT_EQ(video.status, 0) << video.out;
  EXPECT_NE(option_line(video.out, "--test-task INT REQUIRED"), "") << video.out;
}

// Without --render, evaluate writes evaluation.json and trajectories but no video, with a line
// per episode as it finishes; --render films each episode.
TEST(CliVocabulary, EvaluateFilmsOnlyWithRender) {
  const fs::path dir = cradle::test::fresh_dir("cli_vocabulary");
  const std::string config = cradle::test::self_touch_config(dir, 50);
  const std::string evaluate = "evaluate --config " + config + " --duration 20";

  const auto quick = run_cradle(evaluate + " --episodes 2 --save-dir " + (dir / "quick").string());
  ASSERT_EQ(quick.status, 0) << quick.out;
  EXPECT_TRUE(fs::exists(dir / "quick" / "evaluation.json"));
  EXPECT_TRUE(fs::exists(dir / "quick" / "trajectories" / "episode_1.npz"));
  EXPECT_TRUE(!fs::exists(dir / "quick" / "videos") || fs::is_empty(dir / "quick" / "videos"));
  EXPECT_EQ(count_lines(quick.out, "episode 0: score "), 1) << quick.out;
  EXPECT_EQ(count_lines(quick.out, "episode 1: score "), 1) << quick.out;

  const auto filmed =
      run_cradle(evaluate + " --episodes 1 --render --save-dir " + (dir / "filmed").string());
  ASSERT_EQ(filmed.status, 0) << filmed.out;
  EXPECT_TRUE(fs::exists(dir / "filmed" / "evaluation.json"));
  ASSERT_TRUE(fs::exists(dir / "filmed" / "videos" / "episode_0.mp4")) << filmed.out;
  EXPECT_GT(fs::file_size(dir / "filmed" / "videos" / "episode_0.mp4"), 0u);
  EXPECT_EQ(count_lines(filmed.out, "episode "), 1) << filmed.out;

  // --no-render is the default's name.
  const auto plain =
      run_cradle(evaluate + " --episodes 1 --no-render --save-dir " + (dir / "plain").string());
  ASSERT_EQ(plain.status, 0) << plain.out;
  EXPECT_TRUE(!fs::exists(dir / "plain" / "videos") || fs::is_empty(dir / "plain" / "videos"));
  fs::remove_all(dir);
}

// One vocabulary for what every run has: the run folder (--out), the budget in plain env steps
// (--steps), the algorithm (--algo), the seed, --resume, --overwrite and --no-progress; the
// families' reference spellings stay as aliases.
TEST(CliVocabulary, EveryTrainingCommandSpeaksTheSameFlags) {
  const std::map<std::string, std::vector<std::string>> commands = {
      {"train",
       {"--out,--save-dir", "--steps", "--algo", "--seed", "--resume", "--overwrite",
        "--no-progress"}},
      {"tma run",
       {"--out", "--steps", "--student,--algo", "--seed", "--resume", "--overwrite",
        "--no-progress", "--nb_env_steps"}},
      {"sami train",
       {"--out", "--steps", "--method,--algo", "--seed", "--resume", "--overwrite", "--no-progress",
        "--steps-per-env"}},
      {"illustrate", {"--train_for,--steps", "--algorithm,--algo", "--seed"}}};
  for (const auto& [command, flags] : commands) {
    const auto help = run_cradle(command + " --help");
    ASSERT_EQ(help.status, 0) << help.out;
    for (const std::string& flag : flags)
      EXPECT_NE(option_line(help.out, flag + " "), "") << command << " lacks " << flag;
  }

  const fs::path dir = cradle::test::fresh_dir("cli_vocabulary_flags");
  // --steps is env steps in all: SaMI's three training envs get 100 each.
  const auto sami = run_cradle(
      "sami train --env CrippleHalfCheetah --algo tesac --steps 300 --no-progress --out " +
      (dir / "sami").string());
  ASSERT_EQ(sami.status, 0) << sami.out;
  EXPECT_NE(read_text(dir / "sami" / "run.json").find("\"steps\": 300"), std::string::npos);
  EXPECT_NE(read_text(dir / "sami" / "run.json").find("\"envs\": 3"), std::string::npos);
  EXPECT_NE(read_text(dir / "sami" / "run.json").find("\"algorithm\": \"tesac\""),
            std::string::npos);
  // A finished run is replaced only when asked.
  const std::string again = "sami train --env CrippleHalfCheetah --steps 300 --no-progress --out " +
                            (dir / "sami").string();
  EXPECT_EQ(run_cradle(again).status, 1);
  EXPECT_EQ(run_cradle(again + " --overwrite").status, 0);
  // A budget in two units is refused; --steps alone is the run's length.
  EXPECT_EQ(run_cradle("tma run --steps 1000 --nb_env_steps 0.001 --out " + (dir / "tma").string())
                .status,
            1);
  const auto tma = run_cradle(
      "tma run --algo sac --steps 1000 --test_every 1000 --nb_test_episodes 2 --no-progress "
      "--hp learning_starts=300 --hp batch_size=32 --hp pi_layers=16 --hp qf_layers=16 --out " +
      (dir / "tma").string());
  ASSERT_EQ(tma.status, 0) << tma.out;
  EXPECT_EQ(cradle::test::read_lines(dir / "tma" / "progress.csv").size(), 3u);  // 0 and 1000
  const auto train = run_cradle(
      "train --env mimo/reach --steps 128 --hp n_steps=64 --hp "
      "batch_size=64 --eval-episodes 0 --no-progress --out " +
      (dir / "train").string());
  ASSERT_EQ(train.status, 0) << train.out;
  EXPECT_TRUE(fs::exists(dir / "train" / "checkpoints" / "final.ckpt"));
  // A bad curriculum flag is refused before --overwrite removes the run.
  const std::vector<std::string> bad_flags = {"--teacher NoSuchTeacher",
                                              "--task-space " + (dir / "none.yml").string()};
  for (const std::string& bad : bad_flags) {
    const auto refused =
        run_cradle("train --env mimo/reach --steps 128 --no-progress --overwrite " + bad +
                   " --out " + (dir / "train").string());
    EXPECT_EQ(refused.status, 1) << bad << "\n" << refused.out;
    EXPECT_TRUE(fs::exists(dir / "train" / "checkpoints" / "final.ckpt")) << bad;
  }
  fs::remove_all(dir);
}

}  // namespace

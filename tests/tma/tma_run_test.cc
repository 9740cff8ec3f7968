// `cradle tma run`: tiny runs of both students write the run folder of docs/tma_run.md (through
// the one run, train::train), resume continues every file from the checkpoint, and bad input is a
// one-line error.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "fixture.h"

namespace {

namespace fs = std::filesystem;

using cradle::test::read_lines;
using cradle::test::run_cradle;
using cradle::test::RunResult;

std::vector<std::string> cells(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream s(line);
  std::string c;
  while (std::getline(s, c, ',')) out.push_back(c);
  return out;
}

std::vector<nlohmann::json> jsonl(const fs::path& file) {
  std::vector<nlohmann::json> out;
  for (const std::string& l : read_lines(file)) out.push_back(nlohmann::json::parse(l));
  return out;
}

fs::path fresh(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / name;
  fs::remove_all(dir);
  return dir;
}

// Small networks, a short warm-up and 4 test tasks (the 2 x 2 grid) keep a run to seconds.
const std::string kSac =
    "tma run --env stump-tracks --embodiment old_classic_bipedal --student sac --seed 3 "
    "--nb_test_episodes 4 --test_every 1000 --no-progress --hp learning_starts=300 "
    "--hp batch_size=32 --hp pi_layers=16 --hp qf_layers=16 ";

TEST(TmaRun, SacWritesTheRunFolderAndResumes) {
  const fs::path dir = fresh("cradle_tma_run_sac");
  const std::string args =
      kSac +
      "--teacher ALP-GMM --teacher-param fit_rate=6 --teacher-param potential_ks=[2,3] "
      "--allow_expert_knowledge high --keep_periodical_task_samples 500 "
      "--out " +
      dir.string();
  RunResult r = run_cradle(args + " --nb_env_steps 0.002");
  ASSERT_EQ(r.status, 0) << r.out;

  // run.json: arguments, bounds, commit, version.
  const nlohmann::json run = nlohmann::json::parse(std::ifstream(dir / "run.json"));
  EXPECT_EQ(run["arguments"]["teacher"], "ALP-GMM");
  EXPECT_EQ(run["bounds"]["names"], (nlohmann::json{"stump_height", "obstacle_spacing"}));
  EXPECT_EQ(run["bounds"]["maxs"], (nlohmann::json{3.0, 6.0}));
  EXPECT_TRUE(run.contains("commit"));
  EXPECT_TRUE(run.contains("cradle_version"));
  EXPECT_EQ(run["hyperparameters"]["episode_train_freq"], "10");

  // progress.csv: evaluations 0 (before training), 1 and 2.
  std::vector<std::string> progress = read_lines(dir / "progress.csv");
  ASSERT_EQ(progress.size(), 4u);
  EXPECT_EQ(progress[0],
            "evaluation,env_steps,episodes,wall_s,sps,mean_test_return,std_test_return,"
            "pct_mastered,mean_train_return,gradient_steps,teacher_s");
  EXPECT_EQ(cells(progress[1])[0], "0");
  EXPECT_EQ(cells(progress[1])[1], "0");
  EXPECT_EQ(cells(progress[3])[0], "2");
  EXPECT_EQ(cells(progress[3])[1], "2000");
  const long episodes = std::stol(cells(progress[3])[2]);
  EXPECT_GT(episodes, 3);

  // test_returns.csv: 4 tasks per evaluation; test_set.csv the 2 x 2 grid.
  const std::vector<std::string> tests = read_lines(dir / "test_returns.csv");
  ASSERT_EQ(tests.size(), 1u + 3 * 4);
  EXPECT_EQ(tests[0], "evaluation,env_steps,task_index,return,mastered");
  EXPECT_EQ(cells(tests[12])[2], "3");
  const std::vector<std::string> set = read_lines(dir / "test_set.csv");
  ASSERT_EQ(set.size(), 5u);
  EXPECT_EQ(set[0], "task_index,stump_height,obstacle_spacing");
  EXPECT_EQ(set[4], "3,3,6");

  // logs/teacher.jsonl: one train line per episode (in order), a dump per evaluation.
  std::vector<nlohmann::json> book = jsonl(dir / "logs" / "teacher.jsonl");
  long train = 0, dumps = 0;
  for (const nlohmann::json& j : book) {
    if (j["kind"] == "train") {
      EXPECT_EQ(j["episode"], train++);
      EXPECT_EQ(j["task"].size(), 2u);
      EXPECT_EQ(j["success"], j["return"].get<double>() > 230);
    } else if (j["kind"] == "dump") {
      ++dumps;
      EXPECT_EQ(j["teacher"]["teacher"], "alp_gmm");
    } else {
      EXPECT_EQ(j["kind"], "periodical");
      EXPECT_EQ(j["tasks"].size(), 100u);
    }
  }
  EXPECT_EQ(train, episodes);
  EXPECT_EQ(dumps, 3);
  // The run's own files: a progress row per report, the checkpoints of the last evaluation.
  const std::vector<std::string> rows = read_lines(dir / "logs" / "progress.csv");
  ASSERT_EQ(rows.size(), 3u);  // reports at 1000 and 2000
  // Their last columns are the experiment's: the last evaluation's (at 1000: the one before
  // training; at 2000: the one at 1000) mean test return and share mastered.
  EXPECT_TRUE(rows[0].ends_with(",eval/mean_test_return,eval/pct_mastered")) << rows[0];
  for (size_t k = 1; k < rows.size(); ++k) {
    const std::vector<std::string> row = cells(rows[k] + ","), evaluation = cells(progress[k]);
    ASSERT_GE(row.size(), 2u);
    EXPECT_EQ(row[row.size() - 2], evaluation[5]) << rows[k];
    EXPECT_EQ(row[row.size() - 1], evaluation[7]) << rows[k];
  }
  for (const char* file : {"latest.ckpt", "final.ckpt", "step_2000.ckpt"})
    EXPECT_TRUE(fs::exists(dir / "checkpoints" / file)) << file;
  EXPECT_FALSE(fs::exists(dir / "checkpoints" / "step_1000.ckpt"));  // only the newest kept

  // A row written after the checkpoint (a crash) is cut off on resume and kept aside.
  std::ofstream(dir / "progress.csv", std::ios::app) << "9,9999,1,1,1,1,1,1,1\n";
  r = run_cradle(args + " --nb_env_steps 0.003 --resume");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(read_lines(dir / "progress.after-checkpoint.csv").size(), 1u);
  progress = read_lines(dir / "progress.csv");
  ASSERT_EQ(progress.size(), 5u);
  EXPECT_EQ(cells(progress[4])[0], "3");
  EXPECT_EQ(cells(progress[4])[1], "3000");
  EXPECT_GE(std::stol(cells(progress[4])[2]), episodes);
  EXPECT_EQ(read_lines(dir / "test_returns.csv").size(), 1u + 4 * 4);
  train = 0;
  for (const nlohmann::json& j : jsonl(dir / "logs" / "teacher.jsonl")) {
    if (j["kind"] == "train") {
      EXPECT_EQ(j["episode"], train++);
    }
  }
  EXPECT_EQ(train, std::stol(cells(progress[4])[2]));

  // Resuming with another teacher is refused.
  r = run_cradle(kSac + "--teacher Random --out " + dir.string() +
                 " --nb_env_steps 0.004 --resume");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("cradle: error: --resume: --teacher"), std::string::npos) << r.out;
}

// A log of other columns (another version's) is kept whole beside a fresh one on resume, never
// mixed with the current columns; the evaluations go on being numbered.
TEST(TmaRun, ResumeKeepsALogOfOtherColumnsAside) {
  const fs::path dir = fresh("cradle_tma_run_old_header");
  const std::string args = kSac + "--teacher Random --out " + dir.string();
  RunResult r = run_cradle(args + " --nb_env_steps 0.002");
  ASSERT_EQ(r.status, 0) << r.out;
  std::vector<std::string> old_tests = read_lines(dir / "test_returns.csv");
  old_tests[0] = "evaluation,env_steps,task_index,return,achieved";  // as long as the header
  {
    std::ofstream out(dir / "test_returns.csv", std::ios::trunc);
    for (const std::string& line : old_tests) out << line << "\n";
  }
  r = run_cradle(args + " --nb_env_steps 0.003 --resume");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("test_returns.csv: written with other columns, kept whole as"),
            std::string::npos)
      << r.out;
  EXPECT_EQ(read_lines(dir / "test_returns.before-resume.csv"), old_tests);
  const std::vector<std::string> tests = read_lines(dir / "test_returns.csv");
  ASSERT_EQ(tests.size(), 1u + 4);
  EXPECT_EQ(tests[0], "evaluation,env_steps,task_index,return,mastered");
  EXPECT_EQ(cells(tests[1])[0], "3");
  EXPECT_EQ(cells(tests[1])[1], "3000");
  // progress.csv had the current columns: it goes on.
  EXPECT_EQ(read_lines(dir / "progress.csv").size(), 5u);
}

// A run killed after a checkpoint (its folder put back as the checkpoint left it, later rows and
// all) resumes to the same files as the run that went on from that checkpoint undisturbed.
TEST(TmaRun, AKillAfterACheckpointResumesToTheSameFiles) {
  const fs::path dir = fresh("cradle_tma_run_atomic");
  const std::string args = kSac + "--teacher Random --out " + dir.string();
  ASSERT_EQ(run_cradle(args + " --nb_env_steps 0.002").status, 0);
  const fs::path saved = fresh("cradle_tma_run_atomic_saved");
  fs::copy(dir, saved, fs::copy_options::recursive);

  ASSERT_EQ(run_cradle(args + " --nb_env_steps 0.003 --resume").status, 0);
  EXPECT_FALSE(fs::exists(dir / "checkpoints" / "step_2000.ckpt"));  // only the newest is kept
  EXPECT_TRUE(fs::exists(dir / "checkpoints" / "step_3000.ckpt"));
  const std::vector<std::string> test_returns = read_lines(dir / "test_returns.csv");
  const std::vector<std::string> book = read_lines(dir / "logs" / "teacher.jsonl");
  std::vector<std::string> progress;  // without the timing columns (wall_s, sps, teacher_s)
  for (const std::string& line : read_lines(dir / "progress.csv")) {
    const std::vector<std::string> c = cells(line + ",");
    progress.push_back(c[0] + c[1] + c[2] + c[5] + c[6] + c[7] + c[8] + c[9]);
  }
  // The run's rows: the step and the experiment's columns (restored from the checkpoint).
  auto run_rows = [&] {
    std::vector<std::string> out;
    for (const std::string& line : read_lines(dir / "logs" / "progress.csv")) {
      const std::vector<std::string> c = cells(line + ",");
      out.push_back(c[0] + ";" + c[c.size() - 2] + ";" + c[c.size() - 1]);
    }
    return out;
  };
  const std::vector<std::string> rows = run_rows();
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_NE(rows[3].substr(rows[3].find(';')), ";;") << rows[3];

  // The checkpoint of 2000 steps back, with the files as a kill after 3000 steps left them.
  fs::remove_all(dir / "checkpoints");
  fs::copy(saved / "checkpoints", dir / "checkpoints", fs::copy_options::recursive);
  const RunResult r = run_cradle(args + " --nb_env_steps 0.003 --resume");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(read_lines(dir / "test_returns.csv"), test_returns);
  EXPECT_EQ(read_lines(dir / "logs" / "teacher.jsonl"), book);
  std::vector<std::string> again;
  for (const std::string& line : read_lines(dir / "progress.csv")) {
    const std::vector<std::string> c = cells(line + ",");
    again.push_back(c[0] + c[1] + c[2] + c[5] + c[6] + c[7] + c[8] + c[9]);
  }
  EXPECT_EQ(again, progress);
  EXPECT_EQ(run_rows(), rows);
  // What the first resume wrote after the checkpoint is kept aside, not lost.
  EXPECT_EQ(read_lines(dir / "test_returns.after-checkpoint.csv").size(), 4u);
  fs::remove_all(saved);
}

// A finished run is never replaced silently; --overwrite replaces it; a damaged checkpoint or
// teacher book is a one-line error naming the file, and nothing in the folder changes.
TEST(TmaRun, FinishedRunsAndDamagedFilesAreRefused) {
  const fs::path dir = fresh("cradle_tma_run_refuse");
  const std::string run_args = kSac + "--teacher Random --out " + dir.string();
  const std::string args = run_args + " --nb_env_steps 0.001";
  ASSERT_EQ(run_cradle(args).status, 0);
  const std::vector<std::string> progress = read_lines(dir / "progress.csv");
  RunResult r = run_cradle(args);
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("holds a run ("), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("): give --resume to continue it, --overwrite"), std::string::npos) << r.out;
  EXPECT_EQ(read_lines(dir / "progress.csv"), progress);

  auto one_line_naming = [](const RunResult& res, const std::string& what) {
    EXPECT_EQ(res.status, 1) << res.out;
    EXPECT_EQ(std::count(res.out.begin(), res.out.end(), '\n'), 1) << res.out;
    EXPECT_NE(res.out.find(what), std::string::npos) << res.out;
  };
  const fs::path latest = dir / "checkpoints" / "latest.ckpt";
  const fs::path good = dir / "good.ckpt";
  fs::copy_file(latest, good);
  const std::string resume = run_args + " --nb_env_steps 0.002 --resume";
  for (const char* bad : {"[]", "{", "\x01\x02garbage"}) {
    fs::remove(latest);
    std::ofstream(latest, std::ios::trunc) << bad;
    one_line_naming(run_cradle(resume), "latest.ckpt");
    EXPECT_EQ(read_lines(dir / "progress.csv"), progress) << bad;
  }
  // A run folder of an earlier Cradle (its resume point in latest.json).
  fs::remove(latest);
  fs::copy_file(good, latest);
  std::ofstream(dir / "checkpoints" / "latest.json") << "{}";
  one_line_naming(run_cradle(resume), "written by an earlier Cradle (checkpoints/latest.json)");
  fs::remove(dir / "checkpoints" / "latest.json");
  fs::remove(good);
  const fs::path book_file = dir / "logs" / "teacher.jsonl";
  const std::vector<std::string> book = read_lines(book_file);
  for (const char* bad :
       {"{\"env_steps\": 3}", "{\"kind\": \"train\", \"task\": [1]}", "{\"kind\": \"nonsense\"}"}) {
    {
      std::ofstream out(book_file, std::ios::trunc);
      out << bad << "\n";
      for (const std::string& l : book) out << l << "\n";
    }
    one_line_naming(run_cradle(resume), "teacher.jsonl:1: ");
    EXPECT_EQ(read_lines(dir / "progress.csv"), progress) << bad;
    EXPECT_EQ(read_lines(book_file).size(), book.size() + 1) << bad;
  }
  {
    std::ofstream out(book_file, std::ios::trunc);
    for (const std::string& l : book) out << l << "\n";
  }
  // A book that is gone: the teacher's history cannot be replayed.
  fs::rename(book_file, dir / "book.kept");
  one_line_naming(run_cradle(resume), "teacher.jsonl' is shorter than at the checkpoint");
  EXPECT_EQ(read_lines(dir / "progress.csv"), progress);
  fs::rename(dir / "book.kept", book_file);
  // An output path that cannot be a folder.
  one_line_naming(run_cradle(kSac + "--nb_env_steps 0.001 --out /proc/cradle_x"),
                  "cannot create the run folder '/proc/cradle_x'");
  one_line_naming(run_cradle(kSac + "--nb_env_steps 0.001 --out " + (dir / "run.json").string()),
                  "is a file; expected a run folder");

  r = run_cradle(args + " --overwrite");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(read_lines(dir / "progress.csv").size(), progress.size());
}

TEST(TmaRun, PpoStudentWithStudentReset) {
  const fs::path dir = fresh("cradle_tma_run_ppo");
  const std::string args =
      "tma run --env stump-tracks --student ppo --teacher Random --test_every 500 "
      "--nb_test_episodes 4 --reset_frequency 500 --no-progress --hp n_steps=250 --hp "
      "batch_size=50 --hp shared_layers=16 --hp pi_layers=16 --hp vf_layers= --out " +
      dir.string();
  const RunResult r = run_cradle(args + " --nb_env_steps 0.001");
  ASSERT_EQ(r.status, 0) << r.out;
  const std::vector<std::string> progress = read_lines(dir / "progress.csv");
  ASSERT_EQ(progress.size(), 4u);
  EXPECT_EQ(cells(progress[3])[1], "1000");
  // The checkpoint's run state: one fresh student, from step 500 on.
  std::ifstream in(dir / "checkpoints" / "latest.ckpt", std::ios::binary);
  const std::string ckpt((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(ckpt.find("\"learner_resets\":1"), std::string::npos);
  EXPECT_NE(ckpt.find("\"step_offset\":500"), std::string::npos);
  const nlohmann::json summary = nlohmann::json::parse(std::ifstream(dir / "summary.json"));
  EXPECT_EQ(summary["env_steps"], 1000);
  // The preset's return statistics are in the checkpoint: the run resumes with them.
  const RunResult resumed = run_cradle(args + " --nb_env_steps 0.0015 --resume");
  ASSERT_EQ(resumed.status, 0) << resumed.out;
  EXPECT_EQ(read_lines(dir / "progress.csv").size(), 5u);
}

TEST(TmaRun, InterruptStopsAtAReportAndResumes) {
  const fs::path dir = fresh("cradle_tma_run_stop");
  const std::string args = kSac + "--teacher Random --out " + dir.string();
  // A run of a million steps, interrupted once it has begun (its progress.csv exists): it ends
  // by itself with exit 130, not 0, so a campaign does not take it for finished (a run that
  // ignored the signal would meet the 5-minute timeout: 124).
  RunResult r =
      cradle::test::run_cradle_then_signal(args + " --nb_env_steps 1", dir / "progress.csv", "INT");
  ASSERT_EQ(r.status, 130) << r.out;
  EXPECT_NE(r.out.find("stopped by a signal at "), std::string::npos) << r.out;
  const nlohmann::json summary = nlohmann::json::parse(std::ifstream(dir / "summary.json"));
  EXPECT_EQ(summary["stopped"], true);
  const long checkpoint = summary["checkpoint_env_steps"].get<long>();
  EXPECT_EQ(checkpoint % 1000, 0);
  EXPECT_LT(checkpoint, 1'000'000);
  // --resume goes on from the checkpoint written where it stopped to one evaluation more.
  const std::string target = std::to_string((checkpoint + 1000) / 1e6);
  r = run_cradle(args + " --nb_env_steps " + target + " --resume");
  ASSERT_EQ(r.status, 0) << r.out;
  const std::vector<std::string> progress = read_lines(dir / "progress.csv");
  EXPECT_EQ(cells(progress.back())[1], std::to_string(checkpoint + 1000));
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(dir / "summary.json"))["stopped"], false);
}

TEST(TmaRun, BadInputIsAOneLineError) {
  const fs::path dir = fresh("cradle_tma_run_bad");
  for (const char* bad :
       {"--student dqn", "--teacher Teacherless", "--teacher ADR --allow_expert_knowledge none",
        "--allow_expert_knowledge some", "--nb_env_steps -1", "--test_set no_such_set",
        "--embodiment tripod", "--teacher-param fit_rat=3", "--hp n_stepz=3",
        "--teacher-param fit_rate=2 --teacher-param fit_rate=3", "--teacher-param fit_rate"}) {
    const RunResult r =
        run_cradle("tma run --no-progress --out " + dir.string() + " " + std::string(bad));
    EXPECT_EQ(r.status, 1) << bad << ": " << r.out;
    EXPECT_EQ(r.out.rfind("cradle: error: ", 0), 0u) << bad << ": " << r.out;
    EXPECT_EQ(std::count(r.out.begin(), r.out.end(), '\n'), 1) << bad << ": " << r.out;
  }
}

}  // namespace

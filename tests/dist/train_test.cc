// Data-parallel training end to end with real processes: `cradle launch` of 2 ranks on loopback
// (PPO, A2C, SAC) ends with the same parameters on both; a killed rank stops the other with a
// message naming it and the job resumes from its checkpoint; the same run across two network
// namespaces joined by a veth pair, as two hosts would be (root only).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "fixture.h"
#include "ranks.h"

namespace cradle::test {
namespace {

namespace fs = std::filesystem;

// A quick self-touch config (no vision, 100-step episodes) writing to dir/run.
std::string quick_config(const fs::path& dir) {
  return cradle::test::self_touch_config(dir, 100, "save_logs_every: 1000\n");
}

// `cradle train` arguments for a tiny run of `algo`.
std::string train_args(const fs::path& dir, const std::string& algo, long steps) {
  std::string hp = " --hp n_steps=32 batch_size=16 n_epochs=2";
  if (algo == "a2c") hp = " --hp n_steps=8";
  if (algo == "sac" || algo == "td3" || algo == "ddpg") {
    hp = " --hp learning_starts=16 batch_size=16 buffer_size=2000 report_every=16 pi_layers=32,32"
         " qf_layers=32,32";
  }
  return "train --config " + quick_config(dir) + " --algo " + algo + " --envs 1 --threads 1" +
         " --intrinsic body_part_novelty --steps " + std::to_string(steps) +
         " --eval-episodes 0 --checkpoint-every 64 --seed 5 --dist-timeout 30" + hp;
}

// Every "rank R of N: parameter hash H" line's hash, by rank.
std::map<int, std::string> hashes(const std::string& out) {
  std::map<int, std::string> found;
  const std::regex line("rank ([0-9]+) of [0-9]+: parameter hash ([0-9a-f]{16})");
  for (auto it = std::sregex_iterator(out.begin(), out.end(), line); it != std::sregex_iterator();
       ++it) {
    found[std::stoi((*it)[1])] = (*it)[2];
  }
  return found;
}

long last_step(const fs::path& csv) {
  std::ifstream in(csv);
  std::string line, last;
  while (std::getline(in, line)) last = line;
  return last.empty() || !std::isdigit(last[0]) ? -1 : std::stol(last.substr(0, last.find(',')));
}

// A command line split at spaces (the arguments above hold none of their own).
std::vector<std::string> words(const std::string& line) {
  std::vector<std::string> out;
  std::istringstream in(line);
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

class Launch : public testing::TestWithParam<std::string> {};

TEST_P(Launch, TwoRanksEndWithBitwiseIdenticalParameters) {
  const std::string algo = GetParam();
  const fs::path dir = fresh_dir("dist_launch_" + algo);
  const RunResult r = run_cradle("launch --nproc 2 -- cradle " + train_args(dir, algo, 128));
  ASSERT_EQ(r.status, 0) << r.out;
  const std::map<int, std::string> h = hashes(r.out);
  ASSERT_EQ(h.size(), 2u) << r.out;
  EXPECT_EQ(h.at(0), h.at(1));
  // Rank 0 wrote the run's files, counting both ranks' steps; rank 1 logged its envs apart.
  EXPECT_EQ(last_step(dir / "run" / "logs" / "progress.csv"), 128);
  EXPECT_TRUE(fs::exists(dir / "run" / "checkpoints" / "final.ckpt"));
  EXPECT_TRUE(fs::exists(dir / "run" / "ranks" / "1" / "logs"));
  EXPECT_FALSE(fs::exists(dir / "run" / "ranks" / "1" / "checkpoints"));
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Learners, Launch, testing::Values("ppo", "a2c", "sac", "td3", "ddpg"));

// Every env family trains data-parallel through the same run: TeachMyAgent and SaMI by id, 2 ranks,
// the same parameters on both at the end.
class LaunchById : public testing::TestWithParam<std::pair<std::string, std::string>> {};

TEST_P(LaunchById, TwoRanksEndWithBitwiseIdenticalParameters) {
  const auto& [env, algo] = GetParam();
  const fs::path dir = fresh_dir("dist_by_id_" + algo);
  std::string hp = " --hp n_steps=32 batch_size=16 n_epochs=2";
  int envs = 1;
  if (algo == "sac")
    hp = " --hp learning_starts=16 batch_size=16 buffer_size=2000 report_every=16 "
         "pi_layers=32,32 qf_layers=32,32";
  // SaCCM contrasts its two training envs' trajectories; 16-step trajectories, so that updates
  // (and SaNCE's steps) start within the budget.
  if (algo == "saccm") {
    envs = 2;
    hp = " --hp learning_starts=8 batch_size=4 contrast_batch_size=4 buffer_size=50 horizon=16 "
         "report_every=16 train_freq=16 gradient_steps=2 net_arch=16,16 lstm_hidden=16";
  }
  const RunResult r =
      run_cradle("launch --nproc 2 -- cradle train --env " + env + " --algo " + algo + " --envs " +
                 std::to_string(envs) + " --threads 1 --steps " + std::to_string(128 * envs) +
                 " --checkpoint-every " + std::to_string(64 * envs) +
                 " "
                 "--seed 5 --dist-timeout 30 --save-dir " +
                 (dir / "run").string() + hp);
  ASSERT_EQ(r.status, 0) << r.out;
  const std::map<int, std::string> h = hashes(r.out);
  ASSERT_EQ(h.size(), 2u) << r.out;
  EXPECT_EQ(h.at(0), h.at(1));
  EXPECT_EQ(last_step(dir / "run" / "logs" / "progress.csv"), 128 * envs);
  // SaCCM's ranks updated (critics, actor and SaNCE's steps) before they agreed.
  if (algo == "saccm") {
    const std::vector<std::string> rows = read_lines(dir / "run" / "logs" / "progress.csv");
    ASSERT_GE(rows.size(), 2u);
    EXPECT_EQ(rows.front().substr(rows.front().rfind(',') + 1), "losses/sance_weight");
    EXPECT_NE(rows.back().back(), ',') << rows.back();  // the last report's SaNCE weight
  }
  EXPECT_TRUE(fs::exists(dir / "run" / "checkpoints" / "final.ckpt"));
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(
    Families, LaunchById,
    testing::Values(std::pair<std::string, std::string>{"tma/stump-tracks:old_classic_bipedal",
                                                        "ppo"},
                    std::pair<std::string, std::string>{"sami/CrippleHalfCheetah", "sac"},
                    std::pair<std::string, std::string>{"sami/CrippleHalfCheetah", "saccm"}),
    [](const auto& info) { return info.param.second + "_" + std::to_string(info.index); });

// `cradle sami train`, SaMI's own command, takes --distributed too: each rank its own three
// training envs, one SaCCM with the same networks on both ranks at the end, rank 0 writing the run.
TEST(LaunchSami, SamiTrainTwoRanksEndWithBitwiseIdenticalParameters) {
  const fs::path dir = fresh_dir("dist_sami_train");
  const RunResult r = run_cradle(
      "launch --nproc 2 -- cradle sami train --env CrippleHalfCheetah --method SaCCM --seed 3 "
      "--steps 384 --checkpoint-every 32 --distributed --dist-timeout 30 --no-progress --out " +
      (dir / "run").string() +
      " --hp learning_starts=8 --hp batch_size=4 --hp contrast_batch_size=4 --hp buffer_size=50 "
      "--hp horizon=16 --hp report_every=16 --hp train_freq=16 --hp gradient_steps=2 "
      "--hp net_arch=16,16 --hp lstm_hidden=16");
  ASSERT_EQ(r.status, 0) << r.out;
  const std::map<int, std::string> h = hashes(r.out);
  ASSERT_EQ(h.size(), 2u) << r.out;
  EXPECT_EQ(h.at(0), h.at(1));
  // The budget counts both ranks' env steps; only rank 0 reports the run.
  EXPECT_EQ(last_step(dir / "run" / "logs" / "progress.csv"), 384);
  EXPECT_NE(r.out.find("384 env steps, 8 gradient steps"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("checkpoint:"), r.out.rfind("checkpoint:")) << r.out;
  EXPECT_TRUE(fs::exists(dir / "run" / "checkpoints" / "final.ckpt"));
  fs::remove_all(dir);
}

// `cradle tma run` takes --distributed too: each rank its own Stump Tracks env and ALP-GMM teacher,
// SAC with the reference's episode-end updates (the ranks agree on their count), rank 0
// evaluating and writing the run; one student with the same networks on both ranks at the end.
TEST(LaunchTma, TmaRunTwoRanksEndWithBitwiseIdenticalParameters) {
  const fs::path dir = fresh_dir("dist_tma_run");
  const RunResult r = run_cradle(
      "launch --nproc 2 -- cradle tma run --env stump-tracks --student sac --teacher ALP-GMM "
      "--steps 4000 --test_every 2000 --nb_test_episodes 3 --seed 3 --distributed "
      "--dist-timeout 30 --no-progress --out " +
      (dir / "run").string() +
      " --hp learning_starts=1000 --hp batch_size=64 --hp pi_layers=32 --hp qf_layers=32");
  ASSERT_EQ(r.status, 0) << r.out;
  const std::map<int, std::string> h = hashes(r.out);
  ASSERT_EQ(h.size(), 2u) << r.out;
  EXPECT_EQ(h.at(0), h.at(1));
  // Evaluations 0, 1 and 2 by rank 0 (one report line); SAC updated before the end.
  const std::vector<std::string> progress = read_lines(dir / "run" / "progress.csv");
  ASSERT_EQ(progress.size(), 4u);
  std::vector<std::string> cells;
  std::stringstream row(progress[3]);
  for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
  ASSERT_EQ(cells.size(), 11u) << progress[3];
  EXPECT_EQ(cells[0], "2");
  EXPECT_EQ(cells[1], "4000");
  EXPECT_GT(std::stod(cells[9]), 0) << progress[3];  // gradient steps
  EXPECT_EQ(r.out.find("env steps,"), r.out.rfind("env steps,")) << r.out;
  // Each rank's teacher keeps its own book.
  EXPECT_FALSE(read_lines(dir / "run" / "ranks" / "1" / "logs" / "teacher.jsonl").empty());
  EXPECT_TRUE(fs::exists(dir / "run" / "checkpoints" / "final.ckpt"));
  fs::remove_all(dir);
}

TEST(Launch, AFailingRankStopsTheOthersAndIsNamed) {
  const auto start = std::chrono::steady_clock::now();
  const RunResult r = run_cradle(
      "launch --nproc 3 -- sh -c 'if [ \"$RANK\" = 1 ]; then exit 3; fi; exec sleep 60'");
  EXPECT_EQ(r.status, 1) << r.out;
  EXPECT_NE(r.out.find("rank 1 exited with status 3"), std::string::npos) << r.out;
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 30);
}

TEST(Launch, RefusesAMissingCommand) {
  const RunResult r = run_cradle("launch --nproc 2");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.out.find("expected a command after --"), std::string::npos) << r.out;
}

// Ctrl-C to launch reaches both ranks: they agree on a step, rank 0 saves, each exits 130 and so
// does launch (a stopped job is not a finished one); the same command with --resume continues.
TEST(Launch, AStopSignalSavesAndExits130ThenTheJobResumes) {
  const fs::path dir = fresh_dir("dist_stop");
  RunResult r = cradle::test::run_cradle_then_signal(
      "launch --nproc 2 -- cradle " + train_args(dir, "ppo", 1'000'000),
      dir / "run" / "checkpoints" / "latest.ckpt", "INT");
  ASSERT_EQ(r.status, 130) << r.out;
  EXPECT_NE(r.out.find("cradle launch: stopped by a signal"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("rank 0 exited"), std::string::npos) << r.out;
  const long stopped_at = last_step(dir / "run" / "logs" / "progress.csv");
  ASSERT_GE(stopped_at, 64) << r.out;
  ASSERT_LT(stopped_at, 1'000'000);
  r = run_cradle("launch --nproc 2 -- cradle " + train_args(dir, "ppo", stopped_at + 128) +
                 " --resume");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(last_step(dir / "run" / "logs" / "progress.csv"), stopped_at + 128);
  fs::remove_all(dir);
}

TEST(Distributed, AKilledRankStopsTheOtherThenTheJobResumes) {
  const fs::path dir = fresh_dir("dist_kill");
  const int port = free_port();
  const std::string args = train_args(dir, "ppo", 100000);
  std::vector<Process> ranks;
  for (int r = 0; r < 2; ++r) {
    ranks.push_back(
        spawn(words(std::string(CRADLE_BINARY) + " " + args + " --distributed --no-eval-video"),
              {{"WORLD_SIZE", "2"},
               {"RANK", std::to_string(r)},
               {"MASTER_ADDR", "127.0.0.1"},
               {"MASTER_PORT", std::to_string(port)}},
              dir / ("rank" + std::to_string(r) + ".log")));
  }
  // Once a checkpoint exists, rank 1 dies.
  const fs::path latest = dir / "run" / "checkpoints" / "latest.ckpt";
  for (int i = 0; i < 1200 && !fs::exists(latest); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  ASSERT_TRUE(fs::exists(latest)) << ranks[0].output();
  ::kill(ranks[1].pid, SIGKILL);
  EXPECT_EQ(wait_for(ranks[1]), 128 + SIGKILL);
  EXPECT_EQ(wait_for(ranks[0], 40), 1) << ranks[0].output();
  EXPECT_NE(ranks[0].output().find("rank 1 died"), std::string::npos) << ranks[0].output();

  // The whole job resumes from rank 0's last checkpoint and ends identical on both ranks.
  const long checkpoint = last_step(dir / "run" / "logs" / "progress.csv");
  ASSERT_GE(checkpoint, 64);
  const RunResult r = run_cradle("launch --nproc 2 -- cradle " +
                                 train_args(dir, "ppo", checkpoint + 128) + " --resume");
  ASSERT_EQ(r.status, 0) << r.out;
  const std::map<int, std::string> h = hashes(r.out);
  ASSERT_EQ(h.size(), 2u) << r.out;
  EXPECT_EQ(h.at(0), h.at(1));
  EXPECT_GE(last_step(dir / "run" / "logs" / "progress.csv"), checkpoint + 128);
  fs::remove_all(dir);
}

// Two network namespaces joined by a veth pair (10.77.0.1 and 10.77.0.2), one rank in each.
TEST(Distributed, TwoRanksAcrossNetworkNamespaces) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs root to create network namespaces";
  const std::string ns = "cradle" + std::to_string(::getpid());
  const std::string a = ns + "a", b = ns + "b";
  const std::string setup = "ip netns add " + a + " && ip netns add " + b + " && ip link add " + a +
                            "v type veth peer " + b + "v && ip link set " + a + "v netns " + a +
                            " && ip link set " + b + "v netns " + b + " && ip -n " + a +
                            " addr add 10.77.0.1/24 dev " + a + "v && ip -n " + b +
                            " addr add 10.77.0.2/24 dev " + b + "v && ip -n " + a + " link set " +
                            a + "v up && ip -n " + b + " link set " + b + "v up && ip -n " + a +
                            " link set lo up && ip -n " + b + " link set lo up";
  const RunResult made = run(setup + " 2>&1");
  auto cleanup = [&] {
    run("ip netns del " + a + " 2>/dev/null; ip netns del " + b + " 2>/dev/null");
  };
  if (made.status != 0) {
    cleanup();
    GTEST_SKIP() << "cannot create network namespaces here: " << made.out;
  }
  const fs::path dir = fresh_dir("dist_netns");
  const std::string args = train_args(dir, "ppo", 128);
  std::vector<Process> ranks;
  for (int r = 0; r < 2; ++r) {
    ranks.push_back(spawn({"/usr/sbin/ip", "netns", "exec", r == 0 ? a : b, "/bin/sh", "-c",
                           std::string(CRADLE_BINARY) + " " + args + " --distributed"},
                          {{"WORLD_SIZE", "2"},
                           {"RANK", std::to_string(r)},
                           {"MASTER_ADDR", "10.77.0.1"},
                           {"MASTER_PORT", "29533"}},
                          dir / ("rank" + std::to_string(r) + ".log")));
  }
  const int s0 = wait_for(ranks[0], 120), s1 = wait_for(ranks[1], 120);
  cleanup();
  ASSERT_EQ(s0, 0) << ranks[0].output();
  ASSERT_EQ(s1, 0) << ranks[1].output();
  const std::map<int, std::string> h0 = hashes(ranks[0].output()), h1 = hashes(ranks[1].output());
  ASSERT_EQ(h0.size(), 1u);
  ASSERT_EQ(h1.size(), 1u);
  EXPECT_EQ(h0.at(0), h1.at(1));
  fs::remove_all(dir);
}

}  // namespace
}  // namespace cradle::test

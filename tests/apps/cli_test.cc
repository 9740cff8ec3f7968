// The `cradle` binary end to end: exit codes, one-line errors, written files, JSON output.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "fixture.h"

namespace {

namespace fs = std::filesystem;

using CliResult = cradle::test::RunResult;
using cradle::test::read_lines;
using cradle::test::run_cradle;

std::string config(const char* name) { return cradle::test::config_path(name).string(); }

fs::path temp_dir(const char* tag) { return cradle::test::fresh_dir(std::string("cli_") + tag); }

int lines(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

// A quick training config in dir/config.yml (self-touch, no vision, 100-step episodes) whose run
// goes to dir/run; returns the config's path.
std::string write_training_config(const fs::path& dir) {
  return cradle::test::self_touch_config(dir, 100);
}

TEST(Cli, BuildSceneWritesSceneAndTextures) {
  const fs::path dir = temp_dir("build");
  const CliResult r = run_cradle("build-scene --config " + config("config_selftouch.yml") +
                                 " --out " + dir.string());
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(fs::exists(dir / "scene.xml"));
  EXPECT_TRUE(fs::exists(dir / "tex_head_default_right.png"));
  fs::remove_all(dir);
}

TEST(Cli, ModelInfoJsonHasReferenceCounts) {
  const CliResult r = run_cradle("model-info --json --config " + config("config_handregard.yml"));
  ASSERT_EQ(r.status, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["mimo_version"], "v2");
  EXPECT_EQ(j["n_joints"], 91);
  EXPECT_EQ(j["n_actuators"], 17);
  EXPECT_EQ(j["n_torque_sensors"], 53);
  EXPECT_EQ(j["n_bodies"], 54);
  EXPECT_EQ(j["n_geoms"], 74);
  EXPECT_NEAR(j["total_mass"].get<double>(), 10.89991, 0.01);
  EXPECT_NEAR(j["height"].get<double>(), 0.778, 0.008);
  EXPECT_EQ(j["nu"], 17);
  EXPECT_EQ(j["action_dim"], 17);
  EXPECT_EQ(j["observation_sizes"]["observation"], 466);
  EXPECT_EQ(j["observation_sizes"]["eye_left"], 64 * 64 * 3);
}

// Bad input: one line naming the problem, a non-zero exit, no crash.
TEST(Cli, BadConfigGivesOneLineError) {
  const fs::path dir = temp_dir("bad");
  std::ofstream(dir / "bad.yml") << "scene: kitchen\n";
  CliResult r = run_cradle("model-info --config " + (dir / "bad.yml").string());
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(lines(r.out), 1) << r.out;
  EXPECT_NE(r.out.find("scene"), std::string::npos);
  EXPECT_NE(r.out.find("kitchen"), std::string::npos);

  r = run_cradle("model-info --config " + (dir / "missing.yml").string());
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(lines(r.out), 1) << r.out;
  EXPECT_NE(r.out.find("missing.yml"), std::string::npos);

  r = run_cradle("bench --steps 0 --config " + config("config_selftouch.yml"));
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.out.find("--steps"), std::string::npos) << r.out;
  fs::remove_all(dir);
}

TEST(Cli, BenchJsonReportsRatesAndModules) {
  const CliResult r =
      run_cradle("bench --json --steps 200 --config " + config("config_selftouch.yml"));
  ASSERT_EQ(r.status, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_GT(j["env_steps_per_s"].get<double>(), 0);
  EXPECT_GT(j["bare_steps_per_s"].get<double>(), 0);
  EXPECT_GT(j["ratio"].get<double>(), 0.5);
  for (const char* module : {"physics", "touch", "vision", "proprioception", "vestibular"}) {
    EXPECT_TRUE(j["modules_us"].contains(module)) << module;
  }
  EXPECT_GT(j["modules_us"]["touch"].get<double>(), 0);
  EXPECT_EQ(j["modules_us"]["vision"].get<double>(), 0);  // vision is off in this config
}

}  // namespace

namespace {

// ffprobe's frame count, width and height of a video's first stream.
nlohmann::json probe(const fs::path& video) {
  const std::string cmd =
      "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
      "stream=codec_name,width,height,nb_read_frames -of json " +
      video.string();
  return nlohmann::json::parse(cradle::test::run(cmd).out)["streams"][0];
}

TEST(Cli, TestInstallationWritesSceneLogAndVideo) {
  const fs::path dir = temp_dir("install");
  const CliResult r = run_cradle("test-installation --save-dir " + (dir / "out").string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("passed"), std::string::npos);
  EXPECT_TRUE(fs::exists(dir / "out" / "scene" / "scene.xml"));
  EXPECT_TRUE(fs::exists(dir / "out" / "logs" / "training.jsonl"));
  const nlohmann::json v = probe(dir / "out" / "videos" / "test_installation.mp4");
  EXPECT_EQ(v["codec_name"], "h264");
  EXPECT_EQ(v["width"], 480);
  EXPECT_EQ(v["height"], 480);
  EXPECT_EQ(v["nb_read_frames"], "11");
  fs::remove_all(dir);
}

// A random baseline writes a log; evaluate, run from another working directory, scores it and
// writes trajectories, videos (--render), evaluation.json and plots.
TEST(Cli, RandomThenEvaluateFromAnotherDirectory) {
  const fs::path dir = temp_dir("eval");
  cradle::test::self_touch_config(dir, 50, "touch_function: force_vector\n");
  CliResult r = run_cradle("random --config " + (dir / "config.yml").string() + " --train_for 120");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("training score"), std::string::npos) << r.out;

  const fs::path elsewhere = dir / "elsewhere";
  fs::create_directories(elsewhere);
  const CliResult evaluated =
      run_cradle("evaluate --config ../config.yml --episodes 2 --duration 30 --render", elsewhere);
  ASSERT_EQ(evaluated.status, 0) << evaluated.out;
  const fs::path run = dir / "run";
  for (const char* file :
       {"evaluation.json", "trajectories/episode_0.npz", "trajectories/episode_1.npz",
        "plots/training_score.png", "plots/touch_coverage.png"}) {
    EXPECT_TRUE(fs::exists(run / file)) << file;
  }
  const nlohmann::json v = probe(run / "videos" / "episode_1.mp4");
  EXPECT_EQ(v["width"], 720);
  EXPECT_EQ(v["height"], 480);
  EXPECT_EQ(v["nb_read_frames"], "30");
  // The trajectory loads with numpy: qpos per step and one info dict (JSON) per step.
  if (fs::exists("/usr/bin/python3")) {
    const std::string py = "/usr/bin/python3 -c \"import numpy as n, json; d = n.load('" +
                           (run / "trajectories" / "episode_0.npz").string() +
                           "'); print(d['qpos'].shape, json.loads(d['info'][-1])['steps'])\"";
    EXPECT_EQ(cradle::test::run(py).out, "(30, 54) 29\n");
  }
  std::ifstream in(run / "evaluation.json");
  const nlohmann::json report = nlohmann::json::parse(in);
  EXPECT_EQ(report["episodes"].size(), 2u);
  EXPECT_EQ(report["training_log"]["episodes"], 4);  // 0-step entry, 2 full, 1 partial
  EXPECT_TRUE(report["score"].contains("mean"));
  EXPECT_EQ(report["policy_actions"], "random");
  // Sampling needs a policy to sample from: one line, exit 1 (CLI11's "requires").
  const CliResult sampled = run_cradle("evaluate --config ../config.yml --stochastic", elsewhere);
  EXPECT_NE(sampled.status, 0);
  EXPECT_NE(sampled.out.find("--stochastic requires --policy"), std::string::npos) << sampled.out;
  fs::remove_all(dir);
}

}  // namespace

// Train, then resume to a larger budget: the run continues from the checkpoint's step count and
// progress.csv keeps its rows; one written by an older version (other columns) is kept aside.
TEST(Cli, TrainResumesAndKeepsAnOlderProgressFileAside) {
  const fs::path dir = temp_dir("train");
  const std::string train = "train --config " + write_training_config(dir) +
                            " --envs 1 --hp n_steps=128 batch_size=64 n_epochs=1"
                            " --eval-episodes 0 --checkpoint-every 128 --no-eval-video";
  CliResult r = run_cradle(train + " --steps 256");
  ASSERT_EQ(r.status, 0) << r.out;
  const fs::path csv = dir / "run" / "logs" / "progress.csv";
  std::vector<std::string> rows = read_lines(csv);
  ASSERT_EQ(rows.size(), 3u);  // header, steps 128 and 256
  EXPECT_TRUE(rows[0].find("perf/update_seconds") != std::string::npos) << rows[0];
  EXPECT_EQ(rows[2].substr(0, 4), "256,");

  // Same columns: appended.
  r = run_cradle(train + " --steps 384 --resume");
  ASSERT_EQ(r.status, 0) << r.out;
  rows = read_lines(csv);
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[3].substr(0, 4), "384,");

  // Other columns: the old file is renamed, a new one started.
  std::ofstream(csv) << "global_step,time\n128,1.0\n";
  r = run_cradle(train + " --steps 512 --resume");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(read_lines(dir / "run" / "logs" / "progress.before-resume.csv").size(), 2u);
  rows = read_lines(csv);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[1].substr(0, 4), "512,");

  // Resuming with nothing to resume from is a one-line error.
  fs::remove_all(dir / "run" / "checkpoints");
  r = run_cradle(train + " --steps 640 --resume");
  EXPECT_NE(r.status, 0);
  EXPECT_EQ(lines(r.out), 1) << r.out;
}

// Off-policy resume: SAC continues from its checkpoint's step count (the replay buffer refills).
TEST(Cli, SacResumesFromItsCheckpoint) {
  const fs::path dir = temp_dir("train_sac");
  const std::string train = "train --algo sac --config " + write_training_config(dir) +
                            " --envs 1 --hp learning_starts=32 batch_size=16 report_every=64"
                            " --eval-episodes 0 --checkpoint-every 64 --no-eval-video";
  CliResult r = run_cradle(train + " --steps 128");
  ASSERT_EQ(r.status, 0) << r.out;
  r = run_cradle(train + " --steps 192 --resume");
  ASSERT_EQ(r.status, 0) << r.out;
  std::vector<std::string> steps;
  for (const std::string& line : read_lines(dir / "run" / "logs" / "progress.csv")) {
    steps.push_back(line.substr(0, line.find(',')));
  }
  const std::vector<std::string> expected = {"global_step", "64", "128", "192"};
  EXPECT_EQ(steps, expected);
}

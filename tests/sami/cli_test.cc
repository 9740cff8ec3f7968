// `cradle sami`: commands run, a stopped run exits 130 with a checkpoint that resumes, a run killed
// and resumed ends as an uninterrupted one, and wrong input is a one-line error with exit status 1.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "fixture.h"
#include "sami/env.h"

namespace {

namespace fs = std::filesystem;

using cradle::test::read_lines;
using cradle::test::run_cradle;
using cradle::test::RunResult;

TEST(SamiCli, InfoAndRandomRun) {
  const RunResult info = run_cradle("sami info --env PandaPush");
  EXPECT_EQ(info.status, 0) << info.out;
  EXPECT_NE(info.out.find("cell friction 30, cube mass 30"), std::string::npos);
  const RunResult random = run_cradle(
      "sami random --env CrippleAnt --split extreme --episodes 2 --max-steps 5 --seed 1");
  EXPECT_EQ(random.status, 0) << random.out;
  EXPECT_NE(random.out.find("episode 1: return"), std::string::npos);
}

// SIGTERM (a scheduler's time limit) ends `sami train` with a checkpoint and exit 130, not 0, so
// no launcher takes the run for finished; --resume then continues it.
TEST(SamiCli, StopSignalSavesAndExits130) {
  const fs::path dir = cradle::test::fresh_dir("sami_cli_stop");
  const std::string args =
      "sami train --env PandaPush --method CCM --seed 1 --no-progress --out " + dir.string() +
      " --hp net_arch=32,32 --hp lstm_hidden=16 --hp batch_size=4 --hp contrast_batch_size=4"
      " --hp buffer_size=8 --hp train_freq=50 --hp gradient_steps=1 --hp learning_starts=60";
  RunResult r = cradle::test::run_cradle_then_signal(args + " --steps-per-env 1000000",
                                                     dir / "logs" / "progress.csv", "TERM");
  ASSERT_EQ(r.status, 130) << r.out;
  EXPECT_NE(r.out.find("stopped by a signal; continue with: cradle sami train --out"),
            std::string::npos)
      << r.out;
  ASSERT_TRUE(fs::exists(dir / "checkpoints" / "latest.ckpt"));
  // The row at the stop is the last one; resuming runs on to one more row.
  const std::vector<std::string> rows = read_lines(dir / "logs" / "progress.csv");
  ASSERT_GE(rows.size(), 2u);
  const long stopped_at = std::stol(rows.back().substr(0, rows.back().find(',')));
  EXPECT_LT(stopped_at, 6'000'000);
  r = run_cradle("sami train --out " + dir.string() + " --resume --no-progress --steps-per-env " +
                 std::to_string(stopped_at / 6 + 50));
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_GT(read_lines(dir / "logs" / "progress.csv").size(), rows.size());
  fs::remove_all(dir);
}

std::string read_bytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// kill -9 after a checkpoint, then --resume: the same final checkpoint, byte for byte, as a run
// never interrupted (the checkpoint holds the trajectory rings and every generator, and each
// checkpoint starts fresh episodes in both runs).
TEST(SamiCli, KillNineThenResumeEqualsUninterruptedRun) {
  const fs::path killed = cradle::test::fresh_dir("sami_cli_killed");
  const fs::path whole = cradle::test::fresh_dir("sami_cli_whole");
  const auto args = [](const fs::path& dir) {
    return "sami train --env PandaPush --method SaCCM --seed 2 --no-progress --out " +
           dir.string() +
           " --hp net_arch=32,32 --hp lstm_hidden=16 --hp batch_size=4 --hp "
           "contrast_batch_size=4 --hp buffer_size=8 --hp train_freq=10 --hp gradient_steps=1 "
           "--hp learning_starts=60 --checkpoint-every 100";
  };
  // Past the first checkpoint (100 steps per env; a row every 50), then SIGKILL.
  const bool ready =
      cradle::test::run_cradle_then_kill(args(killed) + " --steps-per-env 1000000", [&] {
        return fs::exists(killed / "checkpoints" / "latest.ckpt") &&
               read_lines(killed / "logs" / "progress.csv").size() >= 4;
      });
  ASSERT_TRUE(ready) << "training never passed its first checkpoint";
  RunResult r = run_cradle(args(killed) + " --resume --steps-per-env 1000");
  ASSERT_EQ(r.status, 0) << r.out;
  r = run_cradle(args(whole) + " --steps-per-env 1000");
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_EQ(read_lines(killed / "logs" / "progress.csv").size(), 1u + 1000 / 50);
  EXPECT_EQ(read_bytes(killed / "checkpoints" / "final.ckpt"),
            read_bytes(whole / "checkpoints" / "final.ckpt"));
  fs::remove_all(killed);
  fs::remove_all(whole);
}

TEST(SamiCli, WrongInputIsOneLineError) {
  for (const char* args : {"sami random --env Cheetah", "sami random --env Ant --split hard",
                           "sami bench --env Nope", "sami random --split missing.yml"}) {
    const RunResult out = run_cradle(args);
    EXPECT_EQ(out.status, 1) << args;
    EXPECT_EQ(out.out.rfind("cradle: error: ", 0), 0u) << out.out;
    EXPECT_EQ(out.out.find('\n'), out.out.size() - 1) << out.out;
  }
}

std::unique_ptr<mjModel, void (*)(mjModel*)> load(const fs::path& file) {
  char error[1024] = "";
  return {mj_loadXML(file.c_str(), nullptr, error, sizeof(error)), mj_deleteModel};
}

// The written scene compiles to the task's model: crippled leg 1 of CrippleAnt (extreme split's
// first task set, seed 3) has gear 0 on its two actuators and half-size capsules, every mass is
// the drawn factor times the shared model's, and Panda's table pairs carry Bullet's product.
TEST(SamiCli, BuildSceneWritesTheTasksModel) {
  const fs::path dir = cradle::test::fresh_dir("sami_scene");
  RunResult r = run_cradle(
      "sami build-scene --env CrippleAnt --split extreme --task 0 --seed 3 "
      "--out " +
      (dir / "ant").string());
  ASSERT_EQ(r.status, 0) << r.out;
  const auto ant = load(dir / "ant" / "scene.xml");
  ASSERT_TRUE(ant);
  namespace sami = cradle::sami;
  auto env =
      sami::make_env(sami::EnvId::kCrippleAnt,
                     {sami::split_sets(sami::EnvId::kCrippleAnt, sami::Split::kExtreme)[0]}, 3);
  env->reset(3);
  const mjModel* m = env->model();
  const double factor = env->info().mass;
  EXPECT_NE(factor, 1.0);
  ASSERT_EQ(ant->nbody, m->nbody);
  for (int b = 1; b < m->nbody; ++b) {
    EXPECT_DOUBLE_EQ(ant->body_mass[b], m->body_mass[b]) << b;
    // SaMI scales the mass alone; the file keeps the shared inertia.
    EXPECT_DOUBLE_EQ(ant->body_inertia[3 * b], env->shared_model()->body_inertia[3 * b]) << b;
  }
  ASSERT_EQ(env->info().crippled.size(), 2u);
  int silent = 0;
  for (int a = 0; a < m->nu; ++a) {
    const bool masked = env->action_mask()[a] == 0;
    silent += masked;
    EXPECT_EQ(ant->actuator_gear[6 * a] == 0, masked) << a;
  }
  EXPECT_EQ(silent, 4);  // two legs of two actuators
  for (int g = 0; g < m->ngeom; ++g) {
    EXPECT_NEAR(ant->geom_size[3 * g], m->geom_size[3 * g], 1e-6) << g;
  }
  EXPECT_NE(r.out.find("crippled [" + cradle::sami::joints_text(env->info().crippled, ",") + "]"),
            std::string::npos)
      << r.out;

  r = run_cradle("sami build-scene --env PandaPush --split extreme --task 4 --out " +
                 (dir / "panda").string());
  ASSERT_EQ(r.status, 0) << r.out;
  EXPECT_NE(r.out.find("friction 30, cube mass 1"), std::string::npos) << r.out;
  const auto panda = load(dir / "panda" / "scene.xml");
  ASSERT_TRUE(panda);
  const int table = mj_name2id(panda.get(), mjOBJ_GEOM, "table");
  const int finger = mj_name2id(panda.get(), mjOBJ_GEOM, "leftfinger");
  const int cube = mj_name2id(panda.get(), mjOBJ_GEOM, "object");
  int checked = 0;
  for (int p = 0; p < panda->npair; ++p) {
    const int a = panda->pair_geom1[p], b = panda->pair_geom2[p];
    if ((a == finger && b == table) || (a == table && b == finger)) {
      EXPECT_DOUBLE_EQ(panda->pair_friction[5 * p], 10.0);  // 1 x 30, clipped at 10
      ++checked;
    }
    if ((a == cube && b == table) || (a == table && b == cube)) {
      EXPECT_DOUBLE_EQ(panda->pair_friction[5 * p], 10.0);  // 0.5 x 30, clipped
      ++checked;
    }
  }
  EXPECT_EQ(checked, 2);
  fs::remove_all(dir);
}

// A file, a folder that cannot be created and a non-empty folder without --overwrite are refused
// with one line and nothing written; --overwrite then replaces scene.xml.
TEST(SamiCli, BuildSceneRefusesABadOutWithoutWriting) {
  const fs::path dir = cradle::test::fresh_dir("sami_scene_out");
  const fs::path file = dir / "taken.txt";
  std::ofstream(file) << "keep";
  const fs::path full = dir / "full";
  fs::create_directories(full);
  std::ofstream(full / "notes.txt") << "keep";
  const std::string scene = "sami build-scene --env Hopper --out ";
  for (const std::string& args :
       {scene + file.string(), scene + "/proc/cradle_scene", scene + full.string(),
        scene + (dir / "new").string() + " --task 9",
        "sami build-scene --env Nope --out " + (dir / "new").string()}) {
    const RunResult r = run_cradle(args);
    EXPECT_EQ(r.status, 1) << args << ": " << r.out;
    EXPECT_EQ(r.out.rfind("cradle: error: ", 0), 0u) << r.out;
    EXPECT_EQ(r.out.find('\n'), r.out.size() - 1) << r.out;
  }
  EXPECT_FALSE(fs::exists(full / "scene.xml"));
  EXPECT_FALSE(fs::exists(dir / "new"));
  EXPECT_EQ(cradle::test::read_lines(file), std::vector<std::string>{"keep"});
  const RunResult r = run_cradle(scene + full.string() + " --overwrite");
  EXPECT_EQ(r.status, 0) << r.out;
  EXPECT_TRUE(load(full / "scene.xml"));
  fs::remove_all(dir);
}

}  // namespace

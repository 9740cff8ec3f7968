// Hostile but fair input to `cradle sami`: task-set files with values out of their plausible
// ranges or that are no file, the same run twice in a table, a resume that contradicts its run and
// run folders whose JSON is cut or edited. Each is exit 1 with one line naming the file or flag
// and what was expected, and nothing is written or changed. And MuJoCo's warnings, once a SaMI env
// exists, go to stderr as one line, never onto stdout.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "fixture.h"
#include "sami/env.h"
#include "sami/task.h"

namespace {

namespace fs = std::filesystem;

using cradle::test::run_cradle;
using cradle::test::RunResult;

// Every file under `dir` with its contents: what a refused command must leave as it was.
std::map<std::string, std::string> snapshot(const fs::path& dir) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    std::ostringstream text;
    if (e.is_regular_file()) text << std::ifstream(e.path()).rdbuf();
    files[fs::relative(e.path(), dir).string() + (e.is_directory() ? "/" : "")] = text.str();
  }
  return files;
}

// `cradle <args>` is exit 1 with one line "cradle: error: ..." holding every one of `needles`.
void expect_refused(const std::string& args, const std::vector<std::string>& needles) {
  const RunResult r = run_cradle(args + " </dev/null");
  EXPECT_EQ(r.status, 1) << args << "\n" << r.out;
  EXPECT_EQ(r.out.rfind("cradle: error: ", 0), 0u) << args << "\n" << r.out;
  EXPECT_EQ(r.out.find('\n'), r.out.size() - 1) << args << "\n" << r.out;
  for (const std::string& n : needles)
    EXPECT_NE(r.out.find(n), std::string::npos) << n << "\n" << r.out;
}

std::string write(const fs::path& file, const std::string& text) {
  std::ofstream(file) << text;
  return file.string();
}

TEST(SamiRobust, TaskSetValuesOutOfRangeAreOneLineErrorsNamingTheFile) {
  const fs::path dir = cradle::test::fresh_dir("sami_robust_sets");
  struct Case {
    const char* env;
    const char* sets;
    const char* says;  // besides the file's name
  };
  const std::vector<Case> cases = {
      {"CrippleHalfCheetah", "[{mass: [1e308]}]", "mass factors in [0.01, 100]"},
      {"CrippleHalfCheetah", "[{mass: [1.0, 1e10]}]", "mass factors in [0.01, 100]"},
      {"CrippleHalfCheetah", "[{mass: [-1]}]", "mass factors in [0.01, 100]"},
      {"CrippleHalfCheetah", "[{mass: [0]}]", "mass factors in [0.01, 100]"},
      {"CrippleHalfCheetah", "[{mass: [.nan]}]", "mass factors in [0.01, 100]"},
      {"CrippleHalfCheetah", "[{mass: [.inf]}]", "mass factors in [0.01, 100]"},
      {"CrippleHalfCheetah", "[{mass: []}]", "mass is an empty list"},
      {"CrippleHalfCheetah", "[{damping: [.nan]}]", "does not vary damping"},
      {"CrippleHalfCheetah", "[{mass: [1], mass: [2]}]", "given twice"},
      {"CrippleHalfCheetah", "[]", "task_sets is an empty list"},
      {"HalfCheetah", "[{damping: [.nan]}]", "damping factors in (0, 3]"},
      {"HalfCheetah", "[{damping: [5]}]", "damping factors in (0, 3]"},
      {"HalfCheetah", "[{damping: [0]}]", "damping factors in (0, 3]"},
      {"HalfCheetah", "[{damping: []}]", "damping is an empty list"},
      {"PandaPush", "[{cells: [[1e300, 1]]}]", "table friction in [0, 100]"},
      {"PandaPush", "[{cells: [[1, .nan]]}]", "cube mass in [0.01, 100] kg"},
      {"PandaPush", "[{cells: [[-1, 1]]}]", "table friction in [0, 100]"},
      {"PandaPush", "[{cells: []}]", "has no cells"},
  };
  int n = 0;
  for (const Case& c : cases) {
    const std::string file = write(dir / ("sets" + std::to_string(n++) + ".yml"),
                                   std::string("task_sets: ") + c.sets + "\n");
    const fs::path out = dir / "scene";
    expect_refused(std::string("sami build-scene --env ") + c.env + " --split " + file + " --out " +
                       out.string(),
                   {file, c.says});
    expect_refused(std::string("sami random --env ") + c.env + " --split " + file +
                       " --episodes 1 --max-steps 5 --png " + (dir / "frame.png").string(),
                   {file, c.says});
    EXPECT_FALSE(fs::exists(out)) << c.sets;
    EXPECT_FALSE(fs::exists(dir / "frame.png")) << c.sets;
  }
  // A folder, a missing file and a device named .yml.
  fs::create_directories(dir / "folder.yml");
  expect_refused("sami random --env CrippleHalfCheetah --split " + (dir / "folder.yml").string(),
                 {(dir / "folder.yml").string(), "is a folder; expected a .yml file"});
  expect_refused("sami random --env CrippleHalfCheetah --split " + (dir / "nope.yml").string(),
                 {(dir / "nope.yml").string(), "does not exist"});
  fs::create_symlink("/dev/zero", dir / "zero.yml");
  expect_refused("sami random --env CrippleHalfCheetah --split " + (dir / "zero.yml").string(),
                 {(dir / "zero.yml").string(), "not a regular file"});
  fs::remove_all(dir);
}

// The ranges' ends are in range; programmatic sets are checked the same way.
TEST(SamiRobust, RangeEndsAreAcceptedAndProgrammaticSetsChecked) {
  using cradle::sami::EnvId;
  using cradle::sami::make_env;
  for (EnvId id : {EnvId::kHalfCheetah, EnvId::kSlimHumanoid}) {
    auto env = make_env(id, {{.mass = {0.01, 100}, .damping = {1e-9, 3}}}, 0);
    env->reset(0);
    const auto r = env->step(std::vector<double>(env->spec().action_size, 0.5));
    EXPECT_TRUE(std::isfinite(r.reward));
  }
  EXPECT_NO_THROW(make_env(EnvId::kPandaPush, {{.cells = {{0, 0.01}, {100, 100}}}}, 0));
  try {
    make_env(EnvId::kAnt, {{}, {.mass = {101}}}, 0);
    FAIL() << "a mass factor 101 was accepted";
  } catch (const cradle::UserError& e) {
    EXPECT_EQ(std::string(e.what()),
              "Ant task set 1.mass: mass factor 101 is out of range; expected mass factors in "
              "[0.01, 100]");
  }
  EXPECT_THROW(make_env(EnvId::kHopper, {{.damping = {3.01}}}, 0), cradle::UserError);
  EXPECT_THROW(make_env(EnvId::kPandaPush, {{.cells = {{100.5, 1}}}}, 0), cradle::UserError);
}

// MuJoCo's default warning handler prints on stdout (and writes MUJOCO_LOG.TXT): the first SaMI
// env installs Cradle's, so a warning (here a NaN position in mj_step) is one line on stderr.
TEST(SamiRobust, MujocoWarningsGoToStderrOnceASamiEnvExists) {
  const bool had_log = fs::exists("MUJOCO_LOG.TXT");
  auto env = cradle::sami::make_env(cradle::sami::EnvId::kHopper, {{}}, 0);
  const mjModel* m = env->shared_model();
  std::unique_ptr<mjData, void (*)(mjData*)> d(mj_makeData(m), mj_deleteData);
  d->qpos[1] = std::nan("");
  ::testing::internal::CaptureStdout();
  ::testing::internal::CaptureStderr();
  mj_step(m, d.get());
  std::fflush(stdout);
  const std::string out = ::testing::internal::GetCapturedStdout();
  const std::string err = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(out, "");
  EXPECT_EQ(err.rfind("cradle: MuJoCo warning: Nan, Inf or huge value in QPOS", 0), 0u) << err;
  EXPECT_EQ(err.find('\n'), err.size() - 1) << err;
  EXPECT_GT(d->warning[mjWARN_BADQPOS].number, 0);
  if (!had_log) {
    EXPECT_FALSE(fs::exists("MUJOCO_LOG.TXT"));
  }
}

// An evaluated run folder as `cradle sami evaluate` leaves it (hand-written JSON).
fs::path evaluated_run(const fs::path& dir, const std::string& method, int seed, double score) {
  fs::create_directories(dir);
  write(dir / "eval_train.json", R"({"env": "PandaPush", "method": ")" + method + R"(", "seed": )" +
                                     std::to_string(seed) +
                                     R"(, "split": "train", "success_rate": )" +
                                     std::to_string(score) + R"(, "mean_return": -10})");
  return dir;
}

TEST(SamiRobust, TableRefusesTheSameRunTwice) {
  const fs::path dir = cradle::test::fresh_dir("sami_robust_table");
  const fs::path a = evaluated_run(dir / "a", "CCM", 1, 0.5);
  const fs::path b = evaluated_run(dir / "b", "CCM", 2, 0.7);
  fs::create_directory_symlink(a, dir / "link");
  const std::string out = " --out " + (dir / "table.md").string();
  const RunResult ok = run_cradle("sami table " + a.string() + " " + b.string());
  EXPECT_EQ(ok.status, 0) << ok.out;
  EXPECT_NE(ok.out.find("| CCM | 2 | 0.60 ± 0.14 |"), std::string::npos) << ok.out;
  for (const std::string& again : {a.string(), (dir / "b" / ".." / "a").string(),
                                   (dir / "link").string(), (dir / "a" / "").string()}) {
    expect_refused(
        "sami table " + a.string() + " " + b.string() + " " + again + out,
        {again, "is the run folder " + a.string() + " given again", "expected each run once"});
  }
  expect_refused("sami table " + a.string() + " " + (dir / "missing").string() + out,
                 {(dir / "missing").string(), "is not a folder"});
  // Cut or edited eval JSON: one line naming the file and the key.
  const fs::path bad = dir / "bad";
  fs::create_directories(bad);
  const std::string file = (bad / "eval_train.json").string();
  for (const auto& [json, says] : std::vector<std::pair<std::string, std::string>>{
           {R"({"env": "PandaPush", "method": "CCM", "success_rate": 0.5)", "not valid JSON"},
           {R"([1, 2])", "not a JSON object"},
           {R"({"env": 5, "method": "CCM", "success_rate": 0.5})",
            "\"env\" is 5; expected a string"},
           {R"({"env": "PandaPush", "success_rate": 0.5})",
            "has no key \"method\"; expected a string"},
           {R"({"env": "PandaPush", "method": "CCM", "success_rate": "high"})",
            "\"success_rate\" is \"high\"; expected a number"},
           {R"({"env": "Ant", "method": "CCM", "mean_return": null})",
            "\"mean_return\" is null; expected a number"}}) {
    write(file, json);
    expect_refused("sami table " + a.string() + " " + bad.string() + out, {file, says});
  }
  fs::remove(file);
  fs::create_directories(file);
  expect_refused("sami table " + bad.string() + out, {file, "is a folder"});
  EXPECT_FALSE(fs::exists(dir / "table.md"));
  fs::remove_all(dir);
}

// run.json as `cradle sami train` writes it (no checkpoint: every check comes before it is read).
fs::path trained_run(const fs::path& dir, const std::string& json) {
  fs::create_directories(dir / "logs");
  write(dir / "run.json", json);
  write(dir / "logs" / "progress.csv", "global_step\n6\n");
  return dir;
}

const char* const kRunJson =
    R"({"env": "sami/PandaPush:train", "family": "sami", "algorithm": "saccm", "seed": 7,
        "steps": 600, "envs": 6, "hyperparameters": {"batch_size": "4"}})";

TEST(SamiRobust, ResumeRefusesAnotherEnvMethodOrSeed) {
  const fs::path dir = cradle::test::fresh_dir("sami_robust_resume");
  const fs::path run = trained_run(dir / "run", kRunJson);
  const auto before = snapshot(dir);
  const std::string resume = "sami train --no-progress --resume --out " + run.string();
  const std::string file = (run / "run.json").string();
  expect_refused(resume + " --env CrippleAnt",
                 {file, "is a run of --env PandaPush, not --env CrippleAnt", "leave --env out"});
  expect_refused(resume + " --method CCM",
                 {file, "is a run of --method SaCCM, not --method CCM", "leave --method out"});
  expect_refused(resume + " --seed 8",
                 {file, "is a run of --seed 7, not --seed 8", "leave --seed out"});
  expect_refused(resume + " --env PandaPush --method SaCCM --seed 7 --steps-per-env 200",
                 {(run / "checkpoints" / "latest.ckpt").string()});  // they pass the checks
  EXPECT_EQ(snapshot(dir), before);
  // A `cradle train` run of another split continues there.
  std::string other = kRunJson;
  other.replace(other.find(":train"), 6, ":moderate");
  write(run / "run.json", other);
  expect_refused(resume, {"is a run of sami/PandaPush:moderate on 6 envs, not of SaMI's training",
                          "cradle train --env sami/PandaPush:moderate"});
  fs::remove_all(dir);
}

TEST(SamiRobust, BadRunJsonIsOneLineErrorNamingTheKey) {
  const fs::path dir = cradle::test::fresh_dir("sami_robust_runjson");
  const fs::path run = dir / "run";
  const std::string file = (run / "run.json").string();
  // Every key right but the one each case names.
  const auto run_json = [](const std::string& env, const std::string& algorithm,
                           const std::string& seed, const std::string& steps,
                           const std::string& hyperparameters = "{}") {
    return R"({"env": ")" + env + R"(", "family": "sami", "algorithm": ")" + algorithm +
           R"(", "seed": )" + seed + R"(, "steps": )" + steps +
           R"(, "envs": 6, "hyperparameters": )" + hyperparameters + "}";
  };
  const std::string panda = "sami/PandaPush:train";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {run_json(panda, "saccm", "\"x\"", "600"),
       "\"seed\" is \"x\"; expected an integer from 0 to 18446744073709551615"},
      {run_json(panda, "saccm", "-1", "600"), "\"seed\" is -1; expected an integer"},
      {R"({"env": "sami/PandaPush:train", "family": "sami", "seed": 1, "steps": 600, "envs": 6,
           "hyperparameters": {}})",
       "has no key \"algorithm\"; expected a string"},
      {run_json(panda, "saccm", "1", "0"), "\"steps\" is 0; expected a positive integer"},
      {run_json(panda, "saccm", "1", "600", R"({"batch_size": 4})"),
       "\"hyperparameters\" is {\"batch_size\":4}; expected an object of"},
      {run_json("sami/Cheetah:train", "saccm", "1", "600"), "unknown SaMI env 'Cheetah'"},
      {run_json("mimo/reach", "saccm", "1", "600"), "is not a SaMI env"},
      {run_json(panda, "ppo", "1", "600"), "algorithm 'ppo' is not one of SaMI's learners"},
      {R"({"env": "PandaPush", "method": "SaCCM", "seed": 1, "steps_per_env": 100,
           "hyperparameters": {}})",
       "is an earlier `cradle sami train` run"},
      {R"({"env": "sami/PandaPush:train", "family": "sami", "seed": 1, "steps_per_en)",
       "is not valid JSON"},
      {"[]", "is not a JSON object"},
  };
  for (const auto& [json, says] : cases) {
    fs::remove_all(dir);
    trained_run(run, json);
    const auto before = snapshot(dir);
    expect_refused("sami train --no-progress --resume --out " + run.string(), {file, says});
    expect_refused("sami evaluate --run " + run.string() + " --episodes 1", {file, says});
    EXPECT_EQ(snapshot(dir), before) << json;
  }
  fs::remove_all(dir);
  fs::create_directories(run / "run.json");
  expect_refused("sami train --no-progress --resume --out " + run.string(), {file, "is a folder"});
  expect_refused("sami evaluate --run " + run.string(), {file, "is a folder"});
  fs::remove_all(run);
  expect_refused("sami evaluate --run " + run.string(), {file, "does not exist"});
  fs::remove_all(dir);
}

}  // namespace

// The process vector against the thread vector: bitwise the same trajectories (observations,
// rewards, flags, info values, scores) and training log for the same seeds and actions, the
// proxies' forwarding, and its failure modes (uneven split, a factory's error, a killed worker)
// with no worker left behind.
#include "learn/proc_vector_env.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/jsonl.h"
#include "core/rng.h"
#include "envs/babybench.h"
#include "train/babybench_vector.h"
#include "train/env_vector.h"
#include "vector_snapshot.h"

namespace cradle::learn {
namespace {

namespace fs = std::filesystem;

Config config_of(const char* file, int max_steps) {
  Config config = load_config(fs::path(CRADLE_SOURCE_DIR) / "configs" / file);
  config.max_episode_steps = max_steps;
  return config;
}

using test::random_actions;
using test::snapshot;

bool gone(pid_t pid) { return kill(pid, 0) != 0 && errno == ESRCH; }

TEST(ProcVecEnv, SameTrajectoriesAsTheThreadVector) {
  const Config config = config_of("config_selftouch.yml", 20);
  const auto threads = train::make_babybench_vec_env(config, 4, 2, /*training=*/false, 5);
  const auto procs = train::make_babybench_proc_vec_env(config, 4, 2, /*training=*/false, 5);
  ASSERT_EQ(procs->procs(), 2);
  EXPECT_EQ(procs->observation_space(), threads->observation_space());
  EXPECT_EQ(procs->action_space(), threads->action_space());
  ASSERT_EQ(procs->info(0).size(), threads->info(0).size());
  for (int k = 0; k < threads->info(0).size(); ++k) {
    EXPECT_EQ(procs->info(0).name(k), threads->info(0).name(k));
    EXPECT_EQ(procs->info(0).published(k), threads->info(0).published(k));
  }
  threads->reset(11);
  procs->reset(11);
  EXPECT_EQ(snapshot(*procs), snapshot(*threads));
  Rng rng(3);
  std::vector<double> actions(4 * threads->action_space().size());
  int truncations = 0, touches = 0;
  for (int t = 0; t < 70; ++t) {
    random_actions(threads->action_space(), rng, actions);
    threads->step(actions);
    procs->step(actions);
    ASSERT_EQ(snapshot(*procs), snapshot(*threads)) << "step " << t;
    truncations += procs->truncated()[0];
    for (int i = 0; i < 4; ++i) {
      const envs::Info& info = procs->info(i);
      for (const char* key : {"right_hand_touches", "left_hand_touches"}) {
        touches += static_cast<int>(info.list(info.find(key)).size());
      }
    }
    // Same-step autoreset too, now and then.
    if (t % 25 == 19) {
      threads->reset_ended();
      procs->reset_ended();
      ASSERT_EQ(snapshot(*procs), snapshot(*threads)) << "reset_ended at step " << t;
    }
  }
  EXPECT_EQ(truncations, 3);  // the run went through autoresets
  EXPECT_GT(touches, 0);      // and the info lists carried something
  // The proxies stand for the envs: layouts, reset options and their errors.
  const envs::ObservationLayout* layout = procs->env(0).layout("touch");
  ASSERT_NE(layout, nullptr);
  EXPECT_EQ(layout->values_per_item, threads->env(0).layout("touch")->values_per_item);
  EXPECT_EQ(layout->groups, threads->env(0).layout("touch")->groups);
  EXPECT_EQ(procs->env(0).layout("vestibular"), nullptr);
  for (int i = 0; i < 4; ++i) {
    threads->env(i).set_reset_options({{"randomize_start", 1}});
    procs->env(i).set_reset_options({{"randomize_start", 1}});
  }
  threads->reset(12);
  procs->reset(12);
  EXPECT_EQ(snapshot(*procs), snapshot(*threads));
  try {
    procs->env(3).set_reset_options({{"no_such_option", 1}});
    FAIL() << "an unknown option was taken";
  } catch (const UserError& e) {
    try {
      threads->env(3).set_reset_options({{"no_such_option", 1}});
    } catch (const UserError& t) {
      EXPECT_STREQ(e.what(), t.what());
    }
  }
  EXPECT_THROW(procs->env(0).step(actions), std::logic_error);
  EXPECT_THROW(procs->step(std::span(actions).first(3)), std::invalid_argument);
}

// With vision: each worker renders with its own GL context. The workers start before this
// process renders (Mesa's state does not survive a fork; ctest runs each test in a process of
// its own).
TEST(ProcVecEnv, SameTrajectoriesWithVision) {
  const Config config = config_of("config_handregard.yml", 15);
  ASSERT_TRUE(config.vision_active);
  const auto procs = train::make_babybench_proc_vec_env(config, 2, 2, /*training=*/false, 8);
  const auto threads = train::make_babybench_vec_env(config, 2, 2, /*training=*/false, 8);
  threads->reset(4);
  procs->reset(4);
  EXPECT_EQ(snapshot(*procs), snapshot(*threads));
  Rng rng(9);
  std::vector<double> actions(2 * threads->action_space().size());
  for (int t = 0; t < 20; ++t) {
    random_actions(threads->action_space(), rng, actions);
    threads->step(actions);
    procs->step(actions);
    ASSERT_EQ(snapshot(*procs), snapshot(*threads)) << "step " << t;
  }
}

TEST(ProcVecEnv, TrainingLogIsTheThreadVectors) {
  const fs::path dir = fs::temp_directory_path() / ("cradle_proc_log_" + std::to_string(getpid()));
  std::vector<std::vector<nlohmann::json>> logs;
  for (const bool use_procs : {false, true}) {
    fs::remove_all(dir);
    Config config = config_of("config_selftouch.yml", 10);
    config.save_dir = dir.string();
    {
      std::unique_ptr<VecEnv> vec;
      if (use_procs) {
        vec = train::make_babybench_proc_vec_env(config, 4, 2, /*training=*/true, 9);
      } else {
        vec = train::make_babybench_vec_env(config, 4, 2, /*training=*/true, 9);
      }
      vec->reset(9);
      Rng rng(2);
      std::vector<double> actions(4 * vec->action_space().size());
      for (int t = 0; t < 25; ++t) {
        random_actions(vec->action_space(), rng, actions);
        vec->step(actions);
      }
      vec->env(2).close();  // its partial episode now, the others' when the vector ends
    }
    std::vector<nlohmann::json> entries = read_jsonl(dir / "logs" / "training.jsonl");
    for (nlohmann::json& e : entries) e.erase("wall_time");
    logs.push_back(std::move(entries));
  }
  ASSERT_EQ(logs[0].size(), 4u * 4);
  EXPECT_EQ(logs[1], logs[0]);
  fs::remove_all(dir);
}

TEST(ProcVecEnv, UnevenSplitAndFactoryErrorsAreOneLine) {
  const Config config = config_of("config_selftouch.yml", 10);
  try {
    train::make_babybench_proc_vec_env(config, 3, 2, /*training=*/false, 0);
    FAIL() << "3 envs were split over 2 processes";
  } catch (const UserError& e) {
    EXPECT_STREQ(e.what(),
                 "3 envs do not split evenly over 2 processes; give a number of envs divisible "
                 "by 2");
  }
  const auto assets = envs::make_assets(config);
  auto make = [&](int i) -> std::unique_ptr<envs::Env> {
    if (i == 3) throw UserError("env 3 cannot be built here");
    return std::make_unique<envs::BabyBenchEnv>(assets);
  };
  try {
    ProcVecEnv vec(4, make, 2);
    FAIL() << "the factory's error was lost";
  } catch (const UserError& e) {
    EXPECT_STREQ(e.what(), "env 3 cannot be built here");
  }
}

TEST(ProcVecEnv, KilledWorkerIsNamedAndNoWorkerIsLeft) {
  const Config config = config_of("config_selftouch.yml", 10);
  std::vector<pid_t> pids;
  std::string message;
  {
    const auto vec = train::make_babybench_proc_vec_env(config, 4, 2, /*training=*/false, 0);
    pids = vec->worker_pids();
    ASSERT_EQ(pids.size(), 2u);
    vec->reset(1);
    std::vector<double> actions(4 * vec->action_space().size(), 0.0);
    vec->step(actions);
    ASSERT_EQ(kill(pids[1], SIGKILL), 0);
    try {
      vec->step(actions);
      FAIL() << "a step went through with a dead worker";
    } catch (const UserError& e) {
      message = e.what();
    }
    EXPECT_EQ(message, "env worker 1 (process " + std::to_string(pids[1]) +
                           ", envs 2-3) was killed by signal 9 (Killed)");
    // Every later call says the same.
    try {
      vec->reset(2);
      FAIL() << "a reset went through with a dead worker";
    } catch (const UserError& e) {
      EXPECT_EQ(e.what(), message);
    }
    EXPECT_THROW(vec->env(0).close(), UserError);
  }
  // Both workers are gone and reaped (no zombie keeps the pid).
  for (pid_t pid : pids) EXPECT_TRUE(gone(pid)) << pid;
}

TEST(ProcVecEnv, CleanShutdownReapsEveryWorker) {
  const Config config = config_of("config_selftouch.yml", 10);
  std::vector<pid_t> pids;
  {
    const auto vec = train::make_babybench_proc_vec_env(config, 3, 3, /*training=*/false, 0);
    pids = vec->worker_pids();
    for (pid_t pid : pids) EXPECT_FALSE(gone(pid));
    vec->reset(3);
  }
  ASSERT_EQ(pids.size(), 3u);
  for (pid_t pid : pids) EXPECT_TRUE(gone(pid)) << pid;
}

// Any registered env id, of every family, runs in worker processes with the thread vector's
// trajectories: the factory of the id is called in the workers, with the same indices and seeds.
TEST(ProcVecEnv, EveryFamilyByIdHasTheThreadVectorsTrajectories) {
  for (const char* id :
       {"mimo/reach", "tma/stump-tracks:old_classic_bipedal", "sami/CrippleHalfCheetah:train"}) {
    SCOPED_TRACE(id);
    const std::unique_ptr<VecEnv> procs =
        train::make_env_training(id, 4, 0, 11, nullptr, 0, {}, /*procs=*/2).vec;
    const std::unique_ptr<VecEnv> threads = train::make_env_training(id, 4, 2, 11).vec;
    ASSERT_NE(dynamic_cast<const ProcVecEnv*>(procs.get()), nullptr);
    EXPECT_EQ(dynamic_cast<const ProcVecEnv&>(*procs).procs(), 2);
    procs->reset(5);
    threads->reset(5);
    ASSERT_EQ(snapshot(*procs), snapshot(*threads));
    Rng rng(3);
    std::vector<double> actions(4 * procs->action_space().size());
    int ended = 0;
    for (int t = 0; t < 300; ++t) {
      random_actions(procs->action_space(), rng, actions);
      procs->step(actions);
      threads->step(actions);
      ASSERT_EQ(snapshot(*procs), snapshot(*threads)) << "step " << t;
      for (int i = 0; i < 4; ++i) ended += procs->terminated()[i] || procs->truncated()[i];
    }
    // The walkers fall within 300 random steps: next-step autoreset is compared too.
    if (std::string(id).starts_with("tma/")) {
      EXPECT_GT(ended, 0);
    }
  }
}

// A process that has rendered cannot fork workers that render (Mesa's state does not survive a
// fork): a worker's env says so in one line instead of hanging. Last here: this process renders.
TEST(ProcVecEnv, RefusesToRenderInWorkersOfAProcessThatRendered) {
  const Config config = config_of("config_handregard.yml", 10);
  const auto threads = train::make_babybench_vec_env(config, 1, 1, /*training=*/false, 0);
  threads->reset(0);
  try {
    train::make_babybench_proc_vec_env(config, 2, 2, /*training=*/false, 0);
    FAIL() << "workers were forked after rendering";
  } catch (const UserError& e) {
    EXPECT_STREQ(e.what(),
                 "this process was forked from one that had already rendered, and GL does not "
                 "survive a fork: make process vectors before anything renders");
  }
}

}  // namespace
}  // namespace cradle::learn

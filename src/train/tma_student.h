// A TeachMyAgent student run (`cradle tma run`, the reference's run.py) on the one run path
// (train::train): one student (SAC or PPO with the reference presets) trained on one env of
// TeachMyAgent's benchmark whose tasks a teacher picks, evaluated every test_every env steps on a
// test set with the deterministic policy. This file holds the benchmark's facts (task spaces,
// return bounds, easy corner, test sets, student presets) and the evaluations as the run's
// experiment (train/experiment.h); folder, curriculum, student resets, checkpoints and resume are
// the run's. The run folder (docs/tma_run.md): run.json, progress.csv (one row per evaluation),
// test_returns.csv, test_set.csv, summary.json, logs/progress.csv (one row per report),
// logs/teacher.jsonl, checkpoints/{step_<N>,latest,final}.ckpt (N: the newest evaluation's step).
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "teach/controller.h"
#include "teach/registry.h"
#include "tma/physics.h"
#include "tma/tma_env.h"

namespace cradle::learn {
class GradSync;
}

namespace cradle::train {

// What the benchmark says of one of its envs: the task space and the facts of its experiments.
struct StudentEnv {
  teach::TaskSpace space;
  double reward_lb = -100, reward_ub = 100;         // return bounds for reward scaling
  double success_threshold = tma::kSuccessReturn;   // return above which a task is mastered
  std::optional<teach::DiagGaussian> initial_dist;  // the easy region (high expert knowledge)
  std::vector<teach::Task> test_set;                // empty: teach::default_test_set
};

// TeachMyAgent's benchmark as a student env (the facts of the paper's experiments): envs of the
// given env and body options; Stump Tracks' task space is the criteria's 2-D one
// (stump_height [min_stump_h, max_stump_h], obstacle_spacing [0, max_obstacle_spacing]) with its
// easy corner (no stumps, the largest spacing) for high expert knowledge, Parkour's the
// benchmark's (the env's own task parameters); returns lie in [-150, 350] (Parkour 360);
// `test_set` names a file of data/teachmyagent (empty: the run's default). UserError for an
// unknown body, option or test set.
struct TmaBenchmark {
  double min_stump_h = 0, max_stump_h = 3, max_obstacle_spacing = 6;
  std::string test_set;
};
StudentEnv tma_student_env(const tma::TmaOptions& options, const TmaBenchmark& benchmark = {});

// The reference presets (spec tma_sami.md §4.1, §4.2) as learner hyperparameters; total_steps caps
// SAC's replay buffer (it never overwrites within the run either way). UserError for another
// student.
std::map<std::string, std::string> student_preset(const std::string& student, long total_steps);

// The most --nb_env_steps (millions) a run may ask for: the paper's runs are 20.
constexpr double kTmaMaxMillions = 1000;

// `cradle tma run`'s arguments, by run.py's names, as the CLI and Python give them: run_tma
// checks them, records them in run.json (a resume compares them) and trains the student on
// TeachMyAgent's benchmark env through train::train.
struct TmaRunArguments {
  std::string exp_name = "test", env = "stump-tracks", body = "old_classic_bipedal";
  std::string student = "sac", teacher = "ALP-GMM", expert_knowledge = "high", test_set, out;
  std::vector<std::string> teacher_params, hp;  // "name=value" (a teacher value as JSON)
  double nb_env_steps = 20;                     // millions (run.py's unit)
  long steps = 0;                               // > 0: the budget in env steps instead
  double lr = 0, min_stump_h = 0, max_stump_h = 3, max_obstacle_spacing = 6;
  long test_every = 500000, keep_periodical_task_samples = 0, reset_frequency = 0;
  int nb_test_episodes = 100;
  std::uint64_t seed = 0;
  bool shuffle_dimensions = false, scale_reward = false, resume = false, overwrite = false;
  bool progress_bar = true;
  // Body and Parkour options given (tma::set_option's names: motors_torque, nb_of_bodies, ...).
  std::map<std::string, std::string> env_options;
  std::string commit = "unknown";
  const std::atomic<bool>* stop = nullptr;
  // A data-parallel run's ranks (docs/distributed.md): each its own training env and teacher
  // (seed + rank, its book in ranks/<r>/logs/), one student; rank 0 evaluates and writes the run.
  std::shared_ptr<learn::GradSync> sync;
};
struct TmaRun {
  std::filesystem::path out;  // the run folder (default tma_runs/<exp_name>/<exp_name>_s<seed>)
  // What summary.json says (rank 0's; empty on the other ranks): the run's env steps, episodes
  // and evaluations, this process's wall_s, env_steps_per_s, gradient_steps (SAC's updates; NaN
  // for PPO) and their rate, teacher_s and teacher_share, eval_s, the last pct_mastered, whether
  // it stopped, and checkpoint_env_steps (where --resume continues).
  nlohmann::ordered_json summary;
  bool stopped = false;              // ended before its budget (a signal to any rank stops all)
  std::uint64_t parameter_hash = 0;  // the trained student's (every rank the same)
};
TmaRun run_tma(const TmaRunArguments& arguments);

}  // namespace cradle::train

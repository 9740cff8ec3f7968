// SaMI's experiment (tma_sami.md §6-§8): what the family brings to the one run and its own
// evaluation and tables, for `cradle sami train / evaluate / table` and cradle.sami in Python.
//   sami_experiment.cc  its facts (training task sets, the learners' presets), its run file and
//                       `sami train`, a front end over `cradle train` (train/trainer.h)
//   sami_evaluate.cc    `sami evaluate`: every task set of a split through the one rollout
//   sami_table.cc       the paper's tables and Welch's t-test
//
// `sami train` is `cradle train` with SaMI's flags: the env's training task sets one per env
// (sami/<Env>:train), the method's learner (learn/meta/sami_learner.h: SaCCM is "saccm"), no
// intrinsic reward, and SaMI's budget, horizon and batch sizes. Its folder is a `cradle train`
// run's: run.json, logs/progress.csv and checkpoints/{step_<n>,latest,final}.ckpt (every
// checkpoint_every env steps per env and at the end); `sami evaluate` adds eval_<split>.json /
// .csv and contexts_<split>.csv. `cradle train --env sami/<Env> --algo saccm` makes the same
// folder, which `sami evaluate` reads too.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "envs/registry.h"
#include "learn/grad_sync.h"
#include "sami/task.h"

namespace cradle::train {

// The training task sets, one sub-env each (sami::one_set_per_env of the train split).
std::vector<sami::TaskSet> sami_training_sets(sami::EnvId id);

// SaMI's settings for one of its learners (learn/meta/sami_learner.h) on an env, which `cradle
// train` applies under the user's --hp values: trajectories and progress rows as long as the
// env's episodes (`horizon`, `report_every`; SaMI stores whole episodes), and on Panda push its
// replay and batch sizes (1000 trajectories, batches of 256). Empty for another algorithm.
std::map<std::string, std::string> sami_presets(const envs::EnvSpec& env,
                                                const std::string& algorithm);

struct SamiTrainOptions {
  // On resume, empty takes the run's (run.json); one that differs from the run's is an error.
  std::string env = "PandaPush";
  std::string method = "SaCCM";
  std::uint64_t seed = 0;  // on resume the run's (run.json)
  long steps_per_env = 0;  // 0: SaMI's budget (500,000; PandaPush 1,000,000); on resume the run's
  long steps = 0;          // > 0: env steps in all instead (rounded up to a multiple of the envs)
  std::map<std::string, std::string> hyperparameters;
  std::filesystem::path out;        // run folder; empty: runs/sami/<env>_<method>_<seed>
  bool resume = false;              // continue the run in `out` from its checkpoint
  bool overwrite = false;           // replace a run already in `out` (else refused)
  long checkpoint_every = 100'000;  // env steps per training env between checkpoints
  // Vector steps between progress rows (0: one episode length; on resume the run's).
  long report_every = 0;
  bool progress_bar = true;
  // Set (e.g. by Ctrl-C) to stop at the next progress row with a checkpoint, so that --resume
  // continues from there.
  const std::atomic<bool>* stop = nullptr;
  // A data-parallel run's ranks (TrainOptions::sync): each rank its own training envs, the
  // gradients averaged; the budget counts every rank's env steps. Null: this process alone.
  std::shared_ptr<learn::GradSync> sync;
};

struct SamiTrainResult {
  std::filesystem::path run;
  long steps = 0;                    // env steps (all sub-envs)
  long updates = 0;                  // gradient steps
  double sps = 0;                    // env steps per second, whole run of this call
  double gradient_steps_per_s = 0;   // gradient steps per second of update time
  double last_return = 0;            // mean return of the episodes of the last report
  bool stopped = false;              // ended by `stop` before the budget
  std::filesystem::path checkpoint;  // checkpoints/final.ckpt
  std::uint64_t parameter_hash = 0;  // of the trained networks (the ranks compare it)
};
SamiTrainResult sami_train(const SamiTrainOptions& options);

// A SaMI run folder's run.json (`cradle train`'s) with every key's type checked, a SaMI env and
// learner: a missing or bad file, key or value is a one-line UserError naming run.json and the key.
struct SamiRunFile {
  std::string env_id;     // "sami/CrippleHalfCheetah:train"
  std::string env;        // "CrippleHalfCheetah"
  std::string algorithm;  // "saccm"
  std::string method;     // "SaCCM"
  std::uint64_t seed = 0;
  long envs = 0;                                       // training envs
  long steps = 0;                                      // the budget in env steps, all envs
  long steps_per_env = 0;                              // the budget per env (rounded up)
  std::map<std::string, std::string> hyperparameters;  // the values given
};
SamiRunFile read_sami_run(const std::filesystem::path& run);

struct SamiEvalOptions {
  std::filesystem::path run;
  std::string split = "train";
  int episodes = 10;   // per task set (cell)
  bool video = false;  // eval_<split>.mp4: the first episode of each cell
  std::uint64_t seed = 12345;
};

struct SamiCell {
  std::string name;  // "friction 0.1, mass 1" or the set's values
  int episodes = 0;
  double success_rate = 0, mean_return = 0, std_return = 0;
  double push = 0, roll = 0, pick_and_place = 0;  // Panda: the episodes' skill mix
};
struct SamiEvalResult {
  std::string split;
  std::vector<SamiCell> cells;
  double success_rate = 0, mean_return = 0;  // over all episodes
  // Panda: success and the push / roll / pick-and-place mix are measured (locomotion has none).
  bool skills = false;
  std::filesystem::path json, csv, contexts;
};
SamiEvalResult sami_evaluate(const SamiEvalOptions& options);

// Welch's unequal-variance t-test: t = (mean a - mean b) / sqrt(va/na + vb/nb) and the two-sided
// p from Student's t with the Welch-Satterthwaite degrees of freedom.
struct Welch {
  double t = 0, p = 1, dof = 0;
};
Welch welch_test(const std::vector<double>& a, const std::vector<double>& b);

// The paper's Table 1/2 layout over evaluated runs: per env, method and split, mean +- std over
// seeds of the runs' split scores (Panda: success rate, else mean return), then Welch's t and p of
// SaCCM vs CCM and SaTESAC vs TESAC. Returns the text (markdown); writes it to `out` if given.
std::string sami_table(const std::vector<std::filesystem::path>& runs,
                       const std::filesystem::path& out = {});

}  // namespace cradle::train

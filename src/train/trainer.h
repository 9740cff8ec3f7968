// `cradle train`, the run path of every env family: a BabyBench config or any registered env id
// trained with one learner (and intrinsic rewards, a curriculum, data-parallel ranks) on a vector
// of envs; `cradle sami train` is a front end over it. train() runs its stages in order:
//   check_options    every option, the resumed checkpoint's settings (nothing written before)
//   open_run_folder  a held run refused or replaced; a resumed training log cut back
//   make_curriculum  with a task space: the teacher's controller, env wrapper and book
//   make_vector      the envs (threads, processes or async batches) and intrinsic rewards
//   make_learner     fresh or resumed from checkpoints/latest.ckpt
//   open_logs        run.json, logs/progress.csv (CleanRL names; cut back on resume)
//   train_loop       a progress row per report, checkpoints/step_<n>.ckpt and latest.ckpt, an
//                    experiment's evaluations and fresh learners at their exact steps
//   finish           final.ckpt, the ranks' agreement, plots, the trained policy's evaluation
// BabyBench configs also write the env training log and evaluate as BabyBench does.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <string>

#include "core/config.h"
#include "envs/registry.h"
#include "learn/learner.h"
#include "train/episodes.h"
#include "train/evaluation.h"
#include "train/experiment.h"
#include "train/task_space.h"

namespace cradle::train {

struct TrainOptions {
  // An env id of any family (envs/registry.h; `cradle envs`) but BabyBench's configs, which train
  // as configs, instead of the config's BabyBench env: the same loop, checkpoints, progress.csv,
  // curriculum, intrinsic rewards (those whose observations the env has) and data-parallel
  // ranks, without BabyBench's training log, start randomisation and final evaluation. The MIMo
  // sample tasks' short names (reach, standup, selfbody, catch) are accepted too.
  std::string env;
  // With resume: empty continues the checkpoint's algorithm, another name is refused.
  std::string algorithm = "ppo";
  std::string intrinsic = "body_part_novelty";  // "name[:weight],..."; empty: env reward only
  long steps = 100000;                          // env steps in total (counting a resumed run)
  int envs = 2;
  int threads = 0;  // 0: one per env, at most the cores
  // > 0: PPO and A2C collect through an AsyncVecEnv (`threads` workers) in batches of the first
  // async_batch envs to finish (1 <= async_batch < envs; docs/async.md); 0: lock-step.
  int async_batch = 0;
  // > 0: the envs run in that many worker processes (learn::ProcVecEnv; envs a multiple of it), so
  // that envs which render draw in parallel; 0: threads. BabyBench configs only.
  int procs = 0;
  // LibTorch threads for gradient updates (LearnerOptions): 0: every core for image policies,
  // one for vector policies.
  int update_threads = 0;
  std::uint64_t seed = 0;
  // Continue from <save_dir>/checkpoints/latest.ckpt: its hyperparameters, with `hyperparameters`
  // applied over them; the logs are cut back to what the checkpoint knows.
  bool resume = false;
  // Replace a run already in <save_dir> (its checkpoints, logs and plots are removed first);
  // without it (or resume) a folder that holds a run is refused.
  bool overwrite = false;
  bool randomize_start = false;  // random start postures within joint limits
  long checkpoint_every = 100000;
  // Overrides, by name, over the learner's defaults and what the env's family trains it with
  // (train/families.h: SaMI's learners on an env by id).
  std::map<std::string, std::string> hyperparameters;
  int eval_episodes = 2;  // 0: no final evaluation
  int eval_duration = 1000;
  bool eval_render = true;
  // Also evaluate the random policy the same way (same seeds, no video) into
  // <save_dir>/random_baseline, to report the two scores side by side.
  bool compare_random = false;
  bool progress_bar = true;
  // Extra reward terms (e.g. Python callables), called after the named intrinsic rewards with
  // the same arguments; they may add to the rewards in place.
  learn::RewardHook reward_hook;
  // A curriculum (docs/curricula.md): a task-space YAML whose teacher picks every episode's reset
  // options; `teacher` overrides the file's. Its book goes to <save_dir>/logs/teacher.jsonl.
  std::string task_space;
  std::string teacher;
  // The curriculum itself instead of a task-space file (a family's own, e.g. TeachMyAgent's with
  // its test set and shuffled dimensions); `teacher` still overrides its teacher.
  std::optional<CurriculumSpec> curriculum;
  // A teacher object instead of a name (e.g. Python's, cradle.train(teacher=obj)): made once per
  // rank with the task space and the rank's seed; the file's teacher key may then be left out.
  TeacherFactory teacher_factory;
  // Set (e.g. by a Ctrl-C handler) to stop after the current update with a final checkpoint.
  const std::atomic<bool>* stop = nullptr;
  // Called with each progress row's stats (a data-parallel run's pooled over the ranks), after
  // the row is written: e.g. `cradle sami train`'s summary of its gradient steps.
  std::function<void(const learn::TrainStats&)> on_report;
  // A data-parallel run's ranks (docs/distributed.md); null or one rank: this process alone. Rank
  // r seeds with seed + r; rank 0 writes progress.csv, checkpoints, plots and the evaluation;
  // rank r > 0 logs its envs under <save_dir>/ranks/<r>/. The algorithms whose
  // learn::algorithm_traits say data_parallel.
  std::shared_ptr<learn::GradSync> sync;
  // An experiment's evaluations, files and state (train/experiment.h; e.g. TeachMyAgent's student
  // run). Its evaluations place the checkpoints: checkpoint_every is then unused.
  std::shared_ptr<Experiment> experiment;
  // > 0: a fresh learner (networks, optimiser, buffer; the k-th seeded seed + 7919 k) every this
  // many env steps, the run's step count going on (TeachMyAgent's student resets).
  long reset_every = 0;
  // false: only the newest checkpoints/step_<n>.ckpt is kept (a replay buffer makes each large).
  bool keep_step_checkpoints = true;
  // Options of the env maker (envs::env_maker), e.g. a TeachMyAgent body's motors_torque.
  envs::EnvOptions env_options;
  // Keys written into a fresh run's run.json beside the run's own (e.g. a front end's arguments).
  nlohmann::ordered_json run_json = nlohmann::ordered_json::object();
  // A fresh run's learner starts from this checkpoint's networks and step count (not its run:
  // `cradle illustrate --load_model`); the hyperparameters are the caller's.
  std::string load_model;
  // false: the checkpoints are written from the progress report at or past each multiple of
  // checkpoint_every, inside one learn() call, so that episodes run on across them as in a run
  // without checkpoints (`cradle illustrate`, as the reference's callback saves); a resume then
  // starts fresh episodes. true: learning stops at each checkpoint (an episode boundary).
  bool checkpoints_split_learning = true;
  // Called after each step checkpoint with its file (e.g. to name it as a front end's users
  // expect); rank 0 only.
  std::function<void(const std::filesystem::path& checkpoint)> on_checkpoint;
};

struct TrainResult {
  long steps = 0;
  double seconds = 0;
  double steps_per_second = 0;
  std::optional<double> training_score;  // from the env training log
  std::optional<train::EvaluationReport> evaluation;
  std::optional<train::EvaluationReport> random_evaluation;
  // A run by env id: its trained policy's episodes (train::run_episodes, evaluation.json).
  std::vector<EpisodeOutcome> episodes;
  std::filesystem::path checkpoint;
  std::uint64_t parameter_hash = 0;  // Learner::parameter_hash of the trained networks
};

// With options.env set, only config.save_dir is read.
TrainResult train(const Config& config, const TrainOptions& options);

}  // namespace cradle::train

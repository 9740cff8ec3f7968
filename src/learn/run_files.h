// A training run's files across interruptions: the checkpoint the trainer writes (the learner's
// sealed archive plus the run state and the intrinsic rewards' state, in one atomic file, so they
// can never pair with another step's), and on resume the logs cut back to what that checkpoint
// knows (rows and episodes written after it are kept aside, never lost; a torn last line is
// repaired).
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "learn/learner.h"

namespace cradle::learn {

namespace intrinsic {
class IntrinsicReward;
}

// What a checkpoint records about the run beyond the learner.
struct RunState {
  long steps = 0;     // env steps (the learner's counter)
  long episodes = 0;  // entries of logs/training.jsonl at the checkpoint (after flushing it)
  // The run's intrinsic rewards as Composite::describe() writes them ("" none); absent in
  // checkpoints of earlier builds.
  std::optional<std::string> intrinsic;
  // The run's append-only logs beside the training log (the teacher's book of each rank), by path
  // in the run folder, and their sizes in bytes at the checkpoint: a resume cuts each back to it.
  // Empty for runs without such logs and in checkpoints of earlier builds.
  std::map<std::string, std::uintmax_t> log_sizes;
  // The step counts of each rank's teacher controller (by its book's path): the env steps its
  // envs took, which autoreset steps do not count, so not `steps`.
  std::map<std::string, long> teacher_steps;
  // A run that replaces its learner now and then (TrainOptions::reset_every): the run's env steps
  // before the current learner's first, and how many fresh learners it has made. 0 elsewhere.
  long step_offset = 0;
  long learner_resets = 0;
  // What an experiment of the run keeps across a resume (train/experiment.h), as JSON text; empty
  // for runs without one.
  std::string experiment;
};

// Writes `file`: the learner's checkpoint with sections "run" (RunState as JSON) and
// "intrinsic/<name>" (the files reward->save writes), atomically. A write error (e.g. a full
// disk) is a one-line UserError; `file` is then left as it was and no temp file remains.
void save_run_checkpoint(const std::filesystem::path& file, const Learner& learner,
                         const intrinsic::IntrinsicReward* reward, const RunState& run);
// The run state of a checkpoint written by save_run_checkpoint; restores `reward` (when given)
// from it. UserError for a damaged checkpoint or one written without run state.
RunState load_run_state(const std::filesystem::path& file, intrinsic::IntrinsicReward* reward);

// Cuts logs/training.jsonl back to its first `episodes` entries; later entries and a torn last
// line are appended to training.after-checkpoint.jsonl beside it. Returns how many entries were
// kept (fewer than `episodes` only if the log lost some).
long cut_training_log(const std::filesystem::path& log, long episodes);

// Cuts `file` back to its first `size` bytes (its size at a checkpoint); what follows goes to
// <stem>.after-checkpoint<ext> beside it (appended, never lost) and one line on stderr says so.
// UserError when the file is shorter than `size` (it lost what the checkpoint knows) or cannot be
// cut.
void cut_to_checkpoint(const std::filesystem::path& file, std::uintmax_t size);

// Renames a log written with other columns to <stem>.before-resume<ext> beside it (-2, -3, ...
// after the stem when taken) and returns the new path; UserError when the rename fails.
std::filesystem::path keep_aside_before_resume(const std::filesystem::path& file);

// A log of `header`'s columns (an experiment's CSV), fresh with its header, or with `resume`
// (cut back to the checkpoint already) appended to; one written with other columns (another
// version's) is kept aside whole (keep_aside_before_resume, one line on stderr) and a fresh one
// begins. UserError when it cannot be written.
std::ofstream continue_log(const std::filesystem::path& file, const std::string& header,
                           bool resume);

// progress.csv on resume. When its header is `header`: rows up to `step` are kept, later rows and
// a torn last line go to progress.after-checkpoint.csv beside it, and `append` is true. With
// another header the file is renamed to progress.before-resume[-k].csv and `append` is false.
struct ProgressCut {
  bool append = false;
  std::vector<std::vector<double>> rows;  // the kept rows' values (empty cells NaN)
  std::filesystem::path kept_aside;       // where cut or renamed rows went (empty: none)
};
ProgressCut cut_progress(const std::filesystem::path& csv, const std::string& header, long step);

// Stops training on a non-finite loss (a diverged update): UserError naming the update's step,
// the loss and the last good checkpoint (`checkpoint`, which the failed update never reached).
void check_finite_losses(const TrainStats& stats, const std::filesystem::path& checkpoint);

}  // namespace cradle::learn

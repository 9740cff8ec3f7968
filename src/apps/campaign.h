// Campaigns (docs/campaigns.md): many runs of one command × seeds, on Slurm or a local process
// pool. What `cradle campaign` (every kind of run) and `cradle tma campaign` (TeachMyAgent's
// spelling) share: the campaign file's reader and checks, the launcher and the name rules.
//
// Campaign file: one configuration per line, `#` starts a comment,
//   [--run tma|sami|train] --seeds N[+OFFSET] --name EXP [--campaign C] [--experiment E]
//   [--eval SPLITS --eval-episodes K] <the run command's arguments>
// runs seeds OFFSET..OFFSET+N-1 of `cradle tma run`, `cradle sami train` or `cradle train`; an
// argument written `--*key v` is passed as `--key v` and appends `_key_v` to EXP. A word `''` is
// an empty argument (`--intrinsic ''`: no intrinsic reward). Results tree:
//   RESULTS/EXP/EXP_s<seed>/   the run folder (+ launch.json: kind, command, commit, line; log.txt)
//   RESULTS/EXP/launch/        the line, the commit and the sbatch script of each submission
#pragma once

#include <CLI/CLI.hpp>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace cradle::apps::campaign {

// What a line runs: `cradle tma run`, `cradle sami train` (then `cradle sami evaluate` of the
// line's --eval splits) or `cradle train`.
enum class RunKind { kTma, kSami, kTrain };
const char* kind_name(RunKind kind);  // "tma", "sami", "train"

// One configuration of a campaign file.
struct Line {
  int line_no = 0;
  RunKind kind = RunKind::kTma;
  std::string text;                  // the line as written
  std::string name;                  // experiment folder name (starred arguments appended)
  std::string campaign, experiment;  // analysis labels
  int seeds = 0, offset = 0;         // seeds offset .. offset + seeds - 1
  std::vector<std::string> args;     // the run command's arguments, stars removed
  // --run sami: the splits evaluated after training, episodes per task cell.
  std::vector<std::string> eval_splits;
  int eval_episodes = 10;
  // --run train: the env steps asked for and whether the run evaluates at its end (what a
  // finished run's folder holds).
  long train_steps = 100000;
  bool train_evaluates = true;
};

// Names become folder names: letters, digits and _ - . + (no separators, spaces or shell
// characters), starting with a letter or a digit, at most 200 characters.
bool valid_name(const std::string& s);
extern const char* const kNameRule;
// A byte that would end or break a line of a campaign file or a script (newline, NUL, ...).
bool has_control(const std::string& s);
// A value for error messages: control characters shown as \xNN, cut after 60 characters.
std::string shown(const std::string& s);
// --steps / --nb_env_steps of a TeachMyAgent run: env steps in millions, from 1e-6 to 1000.
void check_steps(double steps, const std::string& what);
// The teacher, its parameters and its expert knowledge, built as `cradle tma run` will build
// them; an error names `where`.
void check_teacher(const std::string& where, const std::string& teacher,
                   const std::vector<std::string>& params, const std::string& expert_knowledge);
std::string number(double v);
void write_text(const std::filesystem::path& file, const std::string& text);
// A word for bash: as is when plain, else single-quoted.
std::string quote(const std::string& s);

// "tma", "sami" or "train" -> its kind; false for another name.
bool parse_kind(const std::string& name, RunKind& kind);
// The SaMI splits a run is evaluated on: train, moderate, extreme.
const std::vector<std::string>& sami_splits();
// "a,b" -> {"a", "b"}.
std::vector<std::string> split_list(const std::string& text);
// Words joined for bash, each quoted where it is not plain.
std::string join_quoted(const std::vector<std::string>& words);
// Output of a shell command (stdout and stderr) and whether it exited with status 0.
std::pair<bool, std::string> capture(const std::string& command);
std::string last_line(const std::string& text);
// This cradle's executable: what a campaign's runs and evaluations call.
std::string self_exe();

// Every configuration of a campaign file; a one-line UserError naming FILE:LINE otherwise.
std::vector<Line> read_campaign(const std::filesystem::path& file);

struct LaunchOptions {
  std::string file, results, runner;
  std::vector<std::string> sbatch_args;
  int jobs = 1, seeds_per_job = 8;
  bool dry_run = false, resume = false, local = false, slurm = false, wait = false;
};
// The launcher's options on `launch` (shared by both spellings).
void add_launch_options(CLI::App& launch, const std::shared_ptr<LaunchOptions>& options);
int launch(const LaunchOptions& options);

// `cradle campaign analyze`: by the kind of the tree's runs (src/apps/campaign_analyze.cc).
int analyze(const std::string& results, const std::string& out, const std::string& baseline);

// The options of `tma campaign generate` (also `campaign generate --kind tma`).
struct TmaGenerateOptions {
  std::string name, teacher, preset = "paper";
  std::vector<std::string> teacher_params;
  bool steps_given = false;
  double steps = 0;        // millions; the preset's unless steps_given
  int seeds = 0;           // 0: the preset's
  int test_episodes = -1;  // 0: the named test sets (paper); N: N default test tasks; -1: preset's
};
std::string generate_tma(const TmaGenerateOptions& options);
// `cradle tma analyze`: python/cradle/tma_analysis.py over a results tree.
int analyze_tma(const std::string& results, const std::string& out, const std::string& baseline);

}  // namespace cradle::apps::campaign

// `cradle campaign generate|launch|analyze`: the headline experiment of each family as one
// campaign file (docs/campaigns.md): TeachMyAgent's benchmark (`cradle tma run`), SaMI's table
// (`cradle sami train` + `cradle sami evaluate`, methods × envs × seeds) and BabyBench's
// intrinsic rewards (`cradle train --config FILE --intrinsic X`), run × seeds on Slurm job arrays
// or a local process pool; the analysis of each kind's results tree is campaign_analyze.cc.
//
// A seed is finished when its folder holds `finished` (written by the launcher after exit status
// 0) or what its command leaves when done: summary.json of a run not stopped (`tma run`);
// checkpoints/final.ckpt at the run's whole budget and every asked evaluation (`sami train`);
// checkpoints/final.ckpt at the asked steps, with evaluation.json when the run evaluates
// (`train`).
#include "apps/campaign.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "apps/commands.h"
#include "core/config.h"
#include "core/error.h"
#include "core/text.h"
#include "envs/registry.h"
#include "learn/checkpoint.h"
#include "learn/intrinsic/reward.h"
#include "learn/learner.h"
#include "learn/meta/methods.h"
#include "learn/registry.h"
#include "train/babybench_vector.h"
#include "train/sami/sami_experiment.h"

extern char** environ;

namespace cradle::apps::campaign {

namespace fs = std::filesystem;

namespace {

// Bounds of a campaign: seeds per line, the largest seed offset, runs per campaign file, local
// jobs, steps of a SaMI or `train` run.
constexpr int kMaxSeeds = 100000;
constexpr int kMaxOffset = 1000000000;
constexpr long kMaxRuns = 1000000;
constexpr int kMaxJobs = 4096;
constexpr size_t kMaxNameLength = 200;
constexpr long kMaxRunSteps = 100000000000L;

// What the launcher knows of each kind: the command, the flags it sets for every seed (an error
// in a file) and the flag that names the run folder.
struct KindSpec {
  RunKind kind;
  const char* name;
  std::vector<std::string> command;  // after the cradle executable
  std::set<std::string> owned;
  const char* folder_flag;
};

const std::vector<KindSpec>& kinds() {
  static const std::vector<KindSpec> specs = {
      {RunKind::kTma,
       "tma",
       {"tma", "run"},
       {"--seed", "--out", "--resume", "--overwrite", "--exp_name"},
       "--out"},
      {RunKind::kSami,
       "sami",
       {"sami", "train"},
       {"--seed", "--out", "--resume", "--overwrite", "--no-progress"},
       "--out"},
      {RunKind::kTrain,
       "train",
       {"train"},
       {"--seed", "--save-dir", "--out", "--resume", "--overwrite"},
       "--save-dir"},
  };
  return specs;
}

const KindSpec& spec_of(RunKind kind) {
  for (const KindSpec& k : kinds()) {
    if (k.kind == kind) return k;
  }
  return kinds().front();
}

// A decimal integer in [min, max].
long parse_count(const std::string& text, const std::string& what, long min, long max) {
  const bool digits =
      !text.empty() && text.size() <= 12 && std::all_of(text.begin(), text.end(), [](char c) {
        return std::isdigit(static_cast<unsigned char>(c));
      });
  if (digits) {
    const long v = std::stol(text);
    if (v >= min && v <= max) return v;
  }
  throw UserError(what + " '" + shown(text) + "' (expected an integer from " + std::to_string(min) +
                  " to " + std::to_string(max) + ")");
}

// The words of a line; `''` or `""` is an empty word (an empty argument such as `--intrinsic ''`).
std::vector<std::string> split_words(const std::string& text) {
  std::istringstream in(text);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w == "''" || w == "\"\"" ? std::string() : w);
  return words;
}

bool is_flag(const std::string& w) { return w.rfind("--", 0) == 0; }

// The SaMI envs, from the env registry's SaMI family (`sami/<Env>:<split>`).
std::vector<std::string> sami_env_names() {
  std::vector<std::string> names;
  for (const envs::EnvSpec& s : envs::env_specs()) {
    if (s.family != "sami" || !s.id.starts_with("sami/")) continue;
    const std::string env = envs::split_env_id(s.id).name;
    if (std::find(names.begin(), names.end(), env) == names.end()) names.push_back(env);
  }
  return names;
}

std::string joined(const std::vector<std::string>& items, const char* sep = ", ") {
  std::string out;
  for (const std::string& s : items) out += (out.empty() ? "" : sep) + s;
  return out;
}

// The checks of one kind on the run's own flags (`values`: the last value of each flag).
void check_run_flags(Line& line, const std::string& where,
                     const std::map<std::string, std::string>& values,
                     const std::vector<std::string>& teacher_params) {
  const auto value = [&](const std::string& flag) -> const std::string* {
    const auto it = values.find(flag);
    return it == values.end() ? nullptr : &it->second;
  };
  if (line.kind == RunKind::kTma) {
    // What the run will read as its teacher (`cradle tma run`'s defaults).
    const std::string* teacher = value("--teacher");
    const std::string* ek = value("--allow_expert_knowledge");
    if (const std::string* steps = value("--nb_env_steps")) {
      char* end = nullptr;
      const double s = std::strtod(steps->c_str(), &end);
      if (end == steps->c_str() || *end != '\0') {
        throw UserError(where + ": --nb_env_steps '" + shown(*steps) +
                        "' (expected millions of env steps, a number)");
      }
      check_steps(s, where + ": --nb_env_steps");
    }
    check_teacher(where, teacher ? *teacher : "ALP-GMM", teacher_params, ek ? *ek : "high");
    return;
  }
  if (line.kind == RunKind::kSami) {
    if (const std::string* env = value("--env")) {
      const std::vector<std::string> envs = sami_env_names();
      if (std::find(envs.begin(), envs.end(), *env) == envs.end()) {
        throw UserError(where + ": --env '" + shown(*env) +
                        "' (expected a SaMI env: " + joined(envs) + ")");
      }
    }
    if (const std::string* method = value("--method")) {
      try {
        learn::meta::method_contrast(*method);
      } catch (const UserError& e) {
        throw UserError(where + ": " + e.what());
      }
    }
    if (const std::string* steps = value("--steps-per-env")) {
      parse_count(*steps, where + ": --steps-per-env", 1, kMaxRunSteps);
    }
    return;
  }
  // `cradle train`: one process per seed, a known algorithm, intrinsic rewards and env.
  for (const char* flag : {"--distributed", "--world-size", "--rank", "--master"}) {
    if (value(flag)) {
      throw UserError(where + ": " + flag +
                      " is not for a campaign (each seed is one process; remove it)");
    }
  }
  const std::string* config = value("--config");
  const std::string* env = value("--env");
  if (!config && !env) throw UserError(where + ": --run train needs --config FILE or --env ID");
  if (config && !fs::exists(*config)) {
    throw UserError(where + ": --config " + shown(*config) + " does not exist");
  }
  try {
    if (env) envs::env_spec(*env);
    if (const std::string* intrinsic = value("--intrinsic")) {
      learn::intrinsic::parse_intrinsic(*intrinsic);
    }
  } catch (const UserError& e) {
    throw UserError(where + ": " + e.what());
  }
  if (const std::string* algo = value("--algo")) {
    const std::vector<std::string> algos = learn::algorithm_names();
    if (std::find(algos.begin(), algos.end(), *algo) == algos.end()) {
      throw UserError(where + ": --algo '" + shown(*algo) + "' (expected one of: " + joined(algos) +
                      ")");
    }
  }
  if (const std::string* steps = value("--steps")) {
    line.train_steps = parse_count(*steps, where + ": --steps", 1, kMaxRunSteps);
  }
  if (const std::string* episodes = value("--eval-episodes")) {
    line.train_evaluates = parse_count(*episodes, where + ": --eval-episodes", 0, 100000) > 0;
  }
}

// One non-comment line -> a configuration; `where` names it in errors. The run's own arguments are
// passed as words (never through a shell unquoted).
Line parse_line(const std::string& text, const std::string& where) {
  if (has_control(text)) {
    throw UserError(where + ": a control character in '" + shown(text) +
                    "' (expected printable words)");
  }
  Line line;
  line.text = text;
  const std::vector<std::string> all = split_words(text);
  // The campaign's own keys first (anywhere on the line): never passed to the run.
  // --eval and --eval-episodes are keys on SaMI lines only (`cradle train` has an
  // --eval-episodes of its own).
  const bool sami_line = [&] {
    for (size_t i = 0; i + 1 < all.size(); ++i) {
      if (all[i] == "--run") return all[i + 1] == "sami";
    }
    return false;
  }();
  std::set<std::string> keys = {"--seeds", "--name", "--campaign", "--experiment", "--run"};
  if (sami_line) keys.insert({"--eval", "--eval-episodes"});
  std::map<std::string, std::string> given;
  std::vector<std::string> words;
  for (size_t i = 0; i < all.size(); ++i) {
    if (!keys.count(all[i])) {
      words.push_back(all[i]);
      continue;
    }
    if (i + 1 >= all.size() || is_flag(all[i + 1]) || all[i + 1].empty()) {
      throw UserError(where + ": " + all[i] + " needs a value");
    }
    if (!given.emplace(all[i], all[i + 1]).second) {
      throw UserError(where + ": " + all[i] + " is given twice (expected it once per line)");
    }
    ++i;
  }
  if (given.count("--run")) {
    const std::string& run = given["--run"];
    bool known = false;
    for (const KindSpec& k : kinds()) {
      if (run == k.name) {
        line.kind = k.kind;
        known = true;
      }
    }
    if (!known)
      throw UserError(where + ": --run '" + shown(run) + "' (expected tma, sami or train)");
  }
  const KindSpec& spec = spec_of(line.kind);
  if (!given.count("--seeds")) throw UserError(where + ": no --seeds N[+OFFSET]");
  if (!given.count("--name")) throw UserError(where + ": no --name EXP");
  {
    const std::string& v = given["--seeds"];
    const size_t plus = v.find('+');
    line.seeds =
        static_cast<int>(parse_count(v.substr(0, plus), where + ": --seeds", 1, kMaxSeeds));
    if (plus != std::string::npos) {
      line.offset = static_cast<int>(
          parse_count(v.substr(plus + 1), where + ": --seeds offset", 0, kMaxOffset));
    }
  }
  for (const char* key : {"--name", "--campaign", "--experiment"}) {
    if (!given.count(key)) continue;
    if (!valid_name(given[key])) {
      throw UserError(where + ": " + key + " '" + shown(given[key]) + "' (" + kNameRule + ")");
    }
  }
  line.name = given["--name"];
  line.campaign = given["--campaign"];
  line.experiment = given["--experiment"];
  if (line.kind != RunKind::kSami && std::find(all.begin(), all.end(), "--eval") != all.end()) {
    throw UserError(where +
                    ": --eval is for --run sami lines (the splits evaluated after "
                    "`cradle sami train`)");
  }
  if (given.count("--eval")) {
    for (const std::string& split : split_list(given["--eval"])) {
      if (std::find(sami_splits().begin(), sami_splits().end(), split) == sami_splits().end() ||
          std::find(line.eval_splits.begin(), line.eval_splits.end(), split) !=
              line.eval_splits.end()) {
        throw UserError(where + ": --eval '" + shown(given["--eval"]) +
                        "' (expected distinct splits among train,moderate,extreme)");
      }
      line.eval_splits.push_back(split);
    }
  }
  if (given.count("--eval-episodes")) {
    line.eval_episodes = static_cast<int>(
        parse_count(given["--eval-episodes"], where + ": --eval-episodes", 1, 100000));
  }

  std::string suffix;
  std::map<std::string, std::string> values;  // flag -> its (last) value, for the kind's checks
  std::vector<std::string> teacher_params;
  for (size_t i = 0; i < words.size(); ++i) {
    const std::string& w = words[i];
    const bool has_value = i + 1 < words.size() && !is_flag(words[i + 1]);
    if (!is_flag(w)) {
      if (line.args.empty()) throw UserError(where + ": '" + shown(w) + "' is not a --flag");
      line.args.push_back(w);
      continue;
    }
    // A starred argument names the experiment too.
    const bool starred = w.rfind("--*", 0) == 0;
    std::string flag = starred ? "--" + w.substr(3) : w;
    if (flag.size() <= 2 || flag[2] == '-' || flag[2] == '*' || flag[2] == '=') {
      throw UserError(where + ": '" + shown(w) + "' is not a --flag");
    }
    // --key=value: the run reads it as --key value.
    std::string inline_value;
    const size_t eq = flag.find('=');
    if (eq != std::string::npos) {
      inline_value = flag.substr(eq + 1);
      flag = flag.substr(0, eq);
    }
    if (spec.owned.count(flag)) {
      throw UserError(where + ": " + flag + " is set by the launcher for every seed of a --run " +
                      spec.name + " line (remove it)");
    }
    const bool valued = has_value || eq != std::string::npos;
    const std::string value = eq != std::string::npos ? inline_value
                              : has_value             ? words[i + 1]
                                                      : "";
    if (starred && (!valued || value.empty())) {
      throw UserError(where + ": " + w + " needs a value (--*key value appends _key_value to " +
                      "the name)");
    }
    // Flags whose values are checked here must have one.
    static const std::set<std::string> kValued = {"--teacher",       "--allow_expert_knowledge",
                                                  "--nb_env_steps",  "--teacher-param",
                                                  "--env",           "--method",
                                                  "--steps-per-env", "--config",
                                                  "--algo",          "--steps",
                                                  "--eval-episodes"};
    if (kValued.count(flag) && !valued) throw UserError(where + ": " + flag + " needs a value");
    if (valued) values[flag] = value;
    if (flag == "--intrinsic" || flag == "--distributed") values[flag] = value;
    if (flag == "--teacher-param") {
      // A vector option: every word up to the next flag.
      if (eq != std::string::npos) teacher_params.push_back(value);
      for (size_t j = i + 1; eq == std::string::npos && j < words.size() && !is_flag(words[j]);
           ++j) {
        teacher_params.push_back(words[j]);
      }
    }
    line.args.push_back(eq != std::string::npos && !starred ? w : flag);
    if (starred) {
      if (eq != std::string::npos) line.args.push_back(value);
      suffix += "_" + flag.substr(2) + "_" + value;
    }
  }
  if (static_cast<long>(line.offset) + line.seeds - 1 > kMaxOffset) {
    throw UserError(where + ": --seeds " + std::to_string(line.seeds) + "+" +
                    std::to_string(line.offset) + " goes past seed " + std::to_string(kMaxOffset) +
                    " (expected a smaller offset)");
  }
  line.name += suffix;
  if (!valid_name(line.name)) {
    throw UserError(where + ": experiment name '" + shown(line.name) + "' is not a folder name (" +
                    kNameRule + ")");
  }
  check_run_flags(line, where, values, teacher_params);
  if (line.experiment.empty()) line.experiment = line.name;
  if (line.campaign.empty()) line.campaign = line.name;
  return line;
}

// ---- launch --------------------------------------------------------------------------------

// One seed of one configuration.
struct SeedRun {
  const Line* line = nullptr;
  int seed = 0;
  fs::path dir;
};

// Whether a run's checkpoints/final.ckpt holds `steps` (a run stopped early saves one too); a
// missing or damaged one holds none.
bool final_checkpoint_holds(const fs::path& dir, long steps) {
  const fs::path final_ckpt = dir / "checkpoints" / "final.ckpt";
  std::error_code ec;
  if (!fs::exists(final_ckpt, ec)) return false;
  try {
    return learn::read_checkpoint_info(final_ckpt).steps >= steps;
  } catch (const std::exception&) {
    return false;
  }
}

// What the kind's command leaves in its folder when it is done.
std::string done_by_files(const SeedRun& r) {
  std::error_code ec;
  switch (r.line->kind) {
    case RunKind::kTma: {
      // summary.json of a run that was not stopped: its whole budget trained and evaluated.
      std::ifstream in(r.dir / "summary.json");
      const nlohmann::json summary = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
      const bool done =
          summary.is_object() && summary.contains("stopped") && summary["stopped"] == false;
      return done ? "summary.json" : "";
    }
    case RunKind::kSami: {
      // The whole budget in checkpoints/final.ckpt, then every evaluation.
      long budget = 0;
      try {
        budget = train::read_sami_run(r.dir).steps;
      } catch (const std::exception&) {
        return "";  // a damaged run is no finished run (the seed runs again and says why)
      }
      if (!final_checkpoint_holds(r.dir, budget)) return "";
      for (const std::string& split : r.line->eval_splits) {
        if (!fs::exists(r.dir / ("eval_" + split + ".json"), ec)) return "";
      }
      return "checkpoints/final.ckpt";
    }
    case RunKind::kTrain:
      if (!final_checkpoint_holds(r.dir, r.line->train_steps)) return "";
      if (r.line->train_evaluates && !fs::exists(r.dir / "evaluation.json", ec)) return "";
      return "checkpoints/final.ckpt";
  }
  return "";
}

bool finished(const SeedRun& r) {
  std::error_code ec;
  return fs::exists(r.dir / "finished", ec) || !done_by_files(r).empty();
}

bool on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  if (path == nullptr) return false;
  std::stringstream dirs(path);
  for (std::string d; std::getline(dirs, d, ':');) {
    if (!d.empty() && ::access((fs::path(d) / program).c_str(), X_OK) == 0) return true;
  }
  return false;
}

// The command that runs one seed of one run, without the launcher's per-seed flags.
std::vector<std::string> run_prefix(const LaunchOptions& o, const Line& line) {
  const KindSpec& spec = spec_of(line.kind);
  std::vector<std::string> argv;
  if (o.runner.empty()) {
    argv = {self_exe()};
    argv.insert(argv.end(), spec.command.begin(), spec.command.end());
  } else {
    argv = split_words(o.runner);
    if (argv.empty()) throw UserError("--runner is empty (expected a command)");
  }
  argv.insert(argv.end(), line.args.begin(), line.args.end());
  if (line.kind == RunKind::kTma) argv.insert(argv.end(), {"--exp_name", line.name});
  if (line.kind == RunKind::kSami) argv.push_back("--no-progress");
  return argv;
}

// How a seed whose folder already holds part of a run goes on: `--resume` from its checkpoint,
// `--overwrite` for a `train` folder that holds logs but no checkpoint yet, or nothing.
std::string continue_flag(const Line& line, const fs::path& dir) {
  std::error_code ec;
  switch (line.kind) {
    case RunKind::kTma:
      return fs::exists(dir / "run.json", ec) ? "--resume" : "";
    case RunKind::kSami:
      return fs::exists(dir / "checkpoints" / "latest.ckpt", ec) ? "--resume" : "";
    case RunKind::kTrain:
      if (fs::exists(dir / "checkpoints" / "latest.ckpt", ec)) return "--resume";
      return fs::exists(dir / "logs" / "progress.csv", ec) ? "--overwrite" : "";
  }
  return "";
}

// The commands of one seed, in order: the run, then (SaMI) the evaluation of each --eval split.
std::vector<std::vector<std::string>> seed_commands(const LaunchOptions& o, const SeedRun& r,
                                                    const std::string& continue_with) {
  std::vector<std::string> argv = run_prefix(o, *r.line);
  argv.insert(argv.end(), {"--seed", std::to_string(r.seed), spec_of(r.line->kind).folder_flag,
                           r.dir.string()});
  if (!continue_with.empty()) argv.push_back(continue_with);
  std::vector<std::vector<std::string>> commands = {argv};
  for (const std::string& split : r.line->eval_splits) {
    commands.push_back({self_exe(), "sami", "evaluate", "--run", r.dir.string(), "--split", split,
                        "--episodes", std::to_string(r.line->eval_episodes)});
  }
  return commands;
}

// The commands as one shell line (`a && b`).
std::string shell_line(const std::vector<std::vector<std::string>>& commands) {
  std::string out;
  for (const auto& c : commands) out += (out.empty() ? "" : " && ") + join_quoted(c);
  return out;
}

// Records how a seed is run beside its results (the reference's copy of script and git log).
void write_launch_json(const LaunchOptions& o, const SeedRun& r, const std::string& commit) {
  fs::create_directories(r.dir);
  nlohmann::json commands = nlohmann::json::array();
  for (const auto& c : seed_commands(o, r, "")) commands.push_back(c);
  const nlohmann::json j = {{"run", kind_name(r.line->kind)},
                            {"campaign", r.line->campaign},
                            {"experiment", r.line->experiment},
                            {"name", r.line->name},
                            {"seed", r.seed},
                            {"args", r.line->args},
                            {"command", commands[0]},
                            {"commands", commands},
                            {"commit", commit},
                            {"cradle_version", CRADLE_VERSION},
                            {"campaign_file", fs::absolute(o.file).string()},
                            {"campaign_line", r.line->line_no},
                            {"line", r.line->text}};
  write_text(r.dir / "launch.json", j.dump(1) + "\n");
}

// The finished marker.
void mark_finished(const fs::path& dir, double wall_s) {
  write_text(dir / "finished",
             nlohmann::json{{"exit_status", 0}, {"wall_s", wall_s}}.dump() + "\n");
}

// Local process pool: at most `jobs` seeds at once, each logging to its folder's log.txt. A seed
// of several commands runs them through /bin/sh, each after the previous one succeeded.
int launch_local(const LaunchOptions& o, const std::vector<SeedRun>& runs) {
  using Clock = std::chrono::steady_clock;
  struct Running {
    const SeedRun* run;
    Clock::time_point start;
  };
  std::map<pid_t, Running> running;
  size_t next = 0, done = 0;
  std::vector<std::string> failures;
  while (next < runs.size() || !running.empty()) {
    // Fill the pool.
    while (next < runs.size() && static_cast<int>(running.size()) < o.jobs) {
      const SeedRun& r = runs[next++];
      const auto commands = seed_commands(o, r, continue_flag(*r.line, r.dir));
      const std::vector<std::string> argv =
          commands.size() == 1 ? commands[0]
                               : std::vector<std::string>{"/bin/sh", "-c", shell_line(commands)};
      std::vector<char*> cargv;
      for (const std::string& a : argv) cargv.push_back(const_cast<char*>(a.c_str()));
      cargv.push_back(nullptr);
      posix_spawn_file_actions_t actions;
      posix_spawn_file_actions_init(&actions);
      const std::string log = (r.dir / "log.txt").string();
      posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_APPEND,
                                       0644);
      posix_spawn_file_actions_adddup2(&actions, 1, 2);
      pid_t pid = 0;
      const int err = posix_spawnp(&pid, cargv[0], &actions, nullptr, cargv.data(), environ);
      posix_spawn_file_actions_destroy(&actions);
      if (err != 0) throw UserError("cannot start '" + argv[0] + "' (expected a program)");
      running[pid] = {&r, Clock::now()};
    }
    // Reap one.
    int status = 0;
    const pid_t pid = ::waitpid(-1, &status, 0);
    if (pid < 0) break;
    const auto it = running.find(pid);
    if (it == running.end()) continue;
    const SeedRun& r = *it->second.run;
    const double wall = std::chrono::duration<double>(Clock::now() - it->second.start).count();
    running.erase(it);
    ++done;
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    if (code == 0) {
      mark_finished(r.dir, wall);
      std::printf("[%zu/%zu] %s seed %d finished in %.1f s\n", done, runs.size(),
                  r.line->name.c_str(), r.seed, wall);
    } else {
      failures.push_back(r.line->name + " seed " + std::to_string(r.seed) + " (exit " +
                         std::to_string(code) + ", log " + (r.dir / "log.txt").string() + ")");
      std::printf("[%zu/%zu] %s seed %d FAILED (exit %d)\n", done, runs.size(),
                  r.line->name.c_str(), r.seed, code);
    }
    std::fflush(stdout);
  }
  for (const std::string& f : failures) std::fprintf(stderr, "failed: %s\n", f.c_str());
  if (!failures.empty()) {
    throw UserError(std::to_string(failures.size()) + " of " + std::to_string(runs.size()) +
                    " runs failed; fix them and launch again with --resume");
  }
  std::printf("%zu runs finished under %s\n", runs.size(), o.results.c_str());
  return 0;
}

// The bash lines that set $resume for a seed folder $dir (continue_flag in bash).
std::string bash_continue_flag(RunKind kind) {
  switch (kind) {
    case RunKind::kTma:
      return "  resume=; [ -e \"$dir/run.json\" ] && resume=--resume\n";
    case RunKind::kSami:
      return "  resume=; [ -e \"$dir/checkpoints/latest.ckpt\" ] && resume=--resume\n";
    case RunKind::kTrain:
      return "  resume=\n"
             "  if [ -e \"$dir/checkpoints/latest.ckpt\" ]; then resume=--resume\n"
             "  elif [ -e \"$dir/logs/progress.csv\" ]; then resume=--overwrite; fi\n";
  }
  return "";
}

// The sbatch script of one line: an array task runs `seeds_per_job` seeds, each pinned to one of
// the task's cores, and skips the seeds already finished.
std::string sbatch_script(const LaunchOptions& o, const Line& line, const std::string& indices,
                          const fs::path& exp_dir) {
  const int k = o.seeds_per_job;
  const std::string seed_dir = (exp_dir / (line.name + "_s")).string();
  const KindSpec& spec = spec_of(line.kind);
  std::ostringstream s;
  s << "#!/bin/bash\n"
    << "#SBATCH --job-name=" << line.name << "\n"
    << "#SBATCH --array=" << indices << "\n"
    << "#SBATCH --ntasks=1\n"
    << "#SBATCH --cpus-per-task=" << std::min(k, line.seeds) << "\n"
    << "#SBATCH --output=" << (exp_dir / "launch" / "slurm_%A_%a.out").string() << "\n";
  for (const std::string& a : o.sbatch_args) s << "#SBATCH " << a << "\n";
  s << "# " << line.name << ": seeds " << line.offset << ".." << line.offset + line.seeds - 1
    << ", " << k << " per array task (cradle campaign launch, --run " << spec.name << ")\n"
    << "set -u\n"
    << "first=$((" << line.offset << " + SLURM_ARRAY_TASK_ID * " << k << "))\n"
    << "last=$((first + " << k << " - 1))\n"
    << "[ $last -gt " << line.offset + line.seeds - 1
    << " ] && last=" << line.offset + line.seeds - 1 << "\n"
    << "# The cores this task may use, one per seed.\n"
    << "cpus=()\n"
    << "for r in $(taskset -cp $$ | sed 's/.*: //' | tr ',' ' '); do\n"
    << "  for ((c = ${r%-*}; c <= ${r#*-}; c++)); do cpus+=($c); done\n"
    << "done\n"
    << "pids=()\n"
    << "slot=0\n"
    << "for seed in $(seq $first $last); do\n"
    << "  dir=" << quote(seed_dir) << "$seed\n"
    << "  [ -e \"$dir/finished\" ] && continue\n"
    << "  mkdir -p \"$dir\"\n"
    << bash_continue_flag(line.kind) << "  cpu=${cpus[$((slot % ${#cpus[@]}))]}\n"
    << "  slot=$((slot + 1))\n"
    << "  (\n"
    << "    start=$(date +%s)\n"
    << "    taskset -c \"$cpu\" " << join_quoted(run_prefix(o, line)) << " --seed \"$seed\" "
    << spec.folder_flag << " \"$dir\" $resume >> \"$dir/log.txt\" 2>&1 || exit $?\n";
  for (const std::string& split : line.eval_splits) {
    s << "    taskset -c \"$cpu\" " << quote(self_exe()) << " sami evaluate --run \"$dir\" --split "
      << split << " --episodes " << line.eval_episodes << " >> \"$dir/log.txt\" 2>&1 || exit $?\n";
  }
  s << "    echo \"{\\\"exit_status\\\": 0, \\\"wall_s\\\": "
       "$(($(date +%s) - start))}\" > \"$dir/finished\"\n"
    << "  ) &\n"
    << "  pids+=($!)\n"
    << "done\n"
    << "status=0\n"
    << "for p in \"${pids[@]}\"; do wait \"$p\" || status=1; done\n"
    << "exit $status\n";
  return s.str();
}

// Array indices "0,2-3" of the blocks that still hold an unfinished seed.
std::string array_indices(const std::vector<int>& blocks) {
  std::string out;
  for (size_t i = 0; i < blocks.size();) {
    size_t j = i;
    while (j + 1 < blocks.size() && blocks[j + 1] == blocks[j] + 1) ++j;
    out += (out.empty() ? "" : ",") + std::to_string(blocks[i]) +
           (j > i ? "-" + std::to_string(blocks[j]) : "");
    i = j + 1;
  }
  return out;
}

int launch_slurm(const LaunchOptions& o, const std::vector<Line>& lines,
                 const std::vector<SeedRun>& runs, const std::string& commit) {
  std::vector<std::string> job_ids;
  // The array tasks of each line, in one pass over the runs (not one per line).
  std::map<const Line*, std::set<int>> blocks;
  for (const SeedRun& r : runs) {
    blocks[r.line].insert((r.seed - r.line->offset) / o.seeds_per_job);
  }
  for (const Line& line : lines) {
    const std::set<int>& block_set = blocks[&line];
    if (block_set.empty()) continue;
    const fs::path exp_dir = fs::path(o.results) / line.name;
    const std::string indices = array_indices({block_set.begin(), block_set.end()});
    const std::string script = sbatch_script(o, line, indices, fs::absolute(exp_dir));
    if (o.dry_run) {
      std::printf("#### %s (%zu array tasks)\n%s\n", line.name.c_str(), block_set.size(),
                  script.c_str());
      continue;
    }
    const fs::path launch_dir = exp_dir / "launch";
    fs::create_directories(launch_dir);
    write_text(launch_dir / "line.txt", line.text + "\n");
    write_text(launch_dir / "commit.txt", commit + "\n");
    const fs::path script_file = launch_dir / (line.name + ".sbatch");
    write_text(script_file, script);
    const auto [ok, id] = capture("sbatch --parsable " + quote(script_file.string()));
    if (!ok || id.empty()) {
      throw UserError("sbatch refused " + script_file.string() + " (" + last_line(id) +
                      "); is Slurm up? (scripts/slurm-local.sh, or --local)");
    }
    const std::string job = last_line(id).substr(0, last_line(id).find(';'));
    // The id goes into an squeue command line: digits only.
    if (job.empty() || !std::all_of(job.begin(), job.end(), [](char c) {
          return std::isdigit(static_cast<unsigned char>(c));
        })) {
      throw UserError("sbatch answered '" + shown(job) + "' for " + script_file.string() +
                      " (expected a job id)");
    }
    job_ids.push_back(job);
    std::printf("submitted %s: job %s, array %s\n", line.name.c_str(), job.c_str(),
                indices.c_str());
    std::fflush(stdout);
  }
  if (o.dry_run || !o.wait || job_ids.empty()) return 0;
  // --wait: until squeue lists none of our jobs, then count the finished seeds.
  std::string list;
  for (const std::string& j : job_ids) list += (list.empty() ? "" : ",") + j;
  for (;;) {
    const auto [ok, queued] = capture("squeue -h -o %i -j " + list);
    if (!ok || queued.empty()) break;
    std::this_thread::sleep_for(std::chrono::seconds(2));
  }
  size_t ok = 0;
  for (const SeedRun& r : runs) ok += finished(r) ? 1 : 0;
  std::printf("%zu of %zu runs finished under %s\n", ok, runs.size(), o.results.c_str());
  if (ok != runs.size()) {
    throw UserError(std::to_string(runs.size() - ok) +
                    " runs did not finish (see their log.txt); launch again with --resume");
  }
  return 0;
}

// Options that reach a script or a command line: nothing that would end a line there. Checked
// before anything is written.
void check_launch_options(const LaunchOptions& o, bool slurm) {
  if (o.jobs < 1 || o.jobs > kMaxJobs) {
    throw UserError("--jobs " + std::to_string(o.jobs) + " (expected 1 to " +
                    std::to_string(kMaxJobs) + ")");
  }
  if (o.local && o.slurm) throw UserError("--local and --slurm exclude each other");
  if (o.results.empty() || has_control(o.results)) {
    throw UserError("--results '" + shown(o.results) +
                    "' (expected a folder name without control characters)");
  }
  if (has_control(o.runner)) {
    throw UserError("--runner '" + shown(o.runner) +
                    "' (expected a command without control characters)");
  }
  if (!o.runner.empty() && split_words(o.runner).empty()) {
    throw UserError("--runner is empty (expected a command)");
  }
  for (const std::string& a : o.sbatch_args) {
    // One `#SBATCH` line each: sbatch reads the option itself, no shell, so one option word.
    if (a.size() < 2 || a[0] != '-' || has_control(a) ||
        a.find_first_of(" \t\"'\\") != std::string::npos) {
      throw UserError("--sbatch '" + shown(a) +
                      "' (expected one sbatch option without spaces, quotes or control "
                      "characters, e.g. --time=20:00:00)");
    }
  }
  if (slurm) {
    // The #SBATCH --output line holds the results folder: one word for sbatch.
    const std::string abs = fs::absolute(o.results).string();
    if (abs.find_first_of(" \t\"'\\") != std::string::npos) {
      throw UserError("--results '" + shown(abs) +
                      "' (expected a folder without spaces or quotes for sbatch's --output)");
    }
  }
}

}  // namespace

const char* kind_name(RunKind kind) { return spec_of(kind).name; }

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> items;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) items.push_back(item);
  return items;
}

const std::vector<std::string>& sami_splits() {
  static const std::vector<std::string> splits = {"train", "moderate", "extreme"};
  return splits;
}

std::string join_quoted(const std::vector<std::string>& words) {
  std::string out;
  for (const std::string& w : words) out += (out.empty() ? "" : " ") + quote(w);
  return out;
}

// Output of a shell command (stdout and stderr) and whether it exited with status 0.
std::pair<bool, std::string> capture(const std::string& command) {
  std::string out;
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return {false, out};
  char buf[4096];
  size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, pipe)) > 0) out.append(buf, n);
  const bool ok = ::pclose(pipe) == 0;
  while (!out.empty() && (out.back() == '\n' || out.back() == ' ')) out.pop_back();
  return {ok, out};
}

// The last line of a command's output, for a one-line error.
std::string last_line(const std::string& text) {
  const size_t nl = text.rfind('\n');
  return nl == std::string::npos ? text : text.substr(nl + 1);
}

std::string self_exe() { return fs::read_symlink("/proc/self/exe").string(); }

bool parse_kind(const std::string& name, RunKind& kind) {
  for (const KindSpec& k : kinds()) {
    if (name == k.name) {
      kind = k.kind;
      return true;
    }
  }
  return false;
}

const char* const kNameRule =
    "expected letters, digits, _ - . + starting with a letter or digit, at most 200 characters";

bool valid_name(const std::string& s) {
  if (s.empty() || s.size() > kMaxNameLength || !std::isalnum(static_cast<unsigned char>(s[0])))
    return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' ||
           c == '+';
  });
}

bool has_control(const std::string& s) {
  return std::any_of(s.begin(), s.end(), [](char c) {
    return std::iscntrl(static_cast<unsigned char>(c)) && c != '\t';
  });
}

// A campaign value in an error: printable, at most 60 characters.
std::string shown(const std::string& s) { return printable(s, 60); }

std::string number(double v) {
  std::ostringstream s;
  s.precision(15);
  s << v;
  return s.str();
}

void write_text(const fs::path& file, const std::string& text) {
  std::ofstream out(file);
  out << text;
  if (!out) throw UserError("cannot write " + file.string());
}

std::string quote(const std::string& s) {
  const bool plain = !s.empty() && std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) ||
           std::string("_-./+=:,").find(c) != std::string::npos;
  });
  if (plain) return s;
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::vector<Line> read_campaign(const fs::path& file) {
  std::error_code ec;
  if (fs::is_directory(file, ec)) {
    throw UserError("campaign file " + file.string() + " is a folder (expected a text file)");
  }
  std::ifstream in(file);
  if (!in) throw UserError("cannot read campaign file " + file.string());
  std::vector<Line> lines;
  std::set<std::string> names;
  std::string text;
  long runs = 0;
  for (int n = 1; std::getline(in, text); ++n) {
    if (!text.empty() && text.back() == '\r') text.pop_back();  // a CRLF file
    const size_t hash = text.find('#');
    const std::string body = text.substr(0, hash);
    const std::string where = file.string() + ":" + std::to_string(n);
    if (split_words(body).empty() && !has_control(body)) continue;
    Line line = parse_line(body, where);
    line.line_no = n;
    if (!names.insert(line.name).second) {
      throw UserError(where + ": experiment '" + line.name + "' appears twice (names must differ)");
    }
    runs += line.seeds;
    if (runs > kMaxRuns) {
      throw UserError(where + ": the campaign reaches " + std::to_string(runs) +
                      " runs (expected at most " + std::to_string(kMaxRuns) + " in one file)");
    }
    lines.push_back(std::move(line));
  }
  if (lines.empty()) throw UserError("campaign file " + file.string() + " has no configuration");
  return lines;
}

int launch(const LaunchOptions& o) {
  const bool slurm = o.slurm || (!o.local && on_path("sbatch"));
  check_launch_options(o, slurm);
  const std::vector<Line> lines = read_campaign(o.file);
  if (o.slurm && !o.dry_run && !on_path("sbatch")) {
    throw UserError("--slurm: sbatch is not on the PATH (start scripts/slurm-local.sh or drop it)");
  }
  // The seeds to run: every seed, less the finished ones under --resume.
  std::vector<SeedRun> runs;
  std::vector<const SeedRun*> detected;  // done by their files, without the launcher's marker
  std::vector<SeedRun> skipped_runs;
  for (const Line& line : lines) {
    for (int s = line.offset; s < line.offset + line.seeds; ++s) {
      SeedRun r{&line, s, fs::path(o.results) / line.name / (line.name + "_s" + std::to_string(s))};
      if (fs::exists(r.dir) && !o.resume && !o.dry_run) {
        throw UserError(r.dir.string() + " exists (use --resume to continue the campaign)");
      }
      if (o.resume && finished(r)) {
        skipped_runs.push_back(r);
        continue;
      }
      runs.push_back(r);
    }
  }
  if (!skipped_runs.empty()) {
    std::printf("--resume: %zu finished seeds skipped\n", skipped_runs.size());
  }
  const std::string commit = [] {
    const auto [ok, c] = capture("git -C " + quote(CRADLE_SOURCE_DIR) + " rev-parse HEAD");
    return ok && !c.empty() ? c : std::string("unknown");
  }();
  if (!o.dry_run) {
    // A seed its files call done gets the launcher's marker, so that a job array's script (which
    // tests the markers only) skips it too.
    for (const SeedRun& r : skipped_runs) {
      std::error_code ec;
      if (!fs::exists(r.dir / "finished", ec)) {
        write_text(
            r.dir / "finished",
            nlohmann::json{{"exit_status", 0}, {"detected_from", done_by_files(r)}}.dump() + "\n");
      }
    }
    for (const SeedRun& r : runs) write_launch_json(o, r, commit);
  }
  if (slurm) return launch_slurm(o, lines, runs, commit);
  if (o.dry_run) {
    for (const SeedRun& r : runs) {
      std::printf("%s\n", shell_line(seed_commands(o, r, continue_flag(*r.line, r.dir))).c_str());
    }
    return 0;
  }
  return launch_local(o, runs);
}

void add_launch_options(CLI::App& lau, const std::shared_ptr<LaunchOptions>& lo) {
  lau.add_option("FILE", lo->file, "Campaign file")->required();
  lau.add_option("--results", lo->results, "Results tree");
  lau.add_option("--jobs", lo->jobs, "Local: runs at once");
  lau.add_flag("--dry-run", lo->dry_run, "Print the sbatch scripts (or local commands) only");
  lau.add_flag("--resume", lo->resume, "Skip finished seeds, continue the others");
  lau.add_flag("--local", lo->local, "Local process pool even where sbatch exists");
  lau.add_flag("--slurm", lo->slurm, "Slurm (an error where sbatch is missing, but --dry-run)");
  lau.add_option("--seeds-per-job", lo->seeds_per_job, "Slurm: seeds per array task")
      ->check(CLI::Range(1, 1024));
  lau.add_option("--sbatch", lo->sbatch_args, "Slurm: extra #SBATCH line, e.g. --time=20:00:00");
  lau.add_flag("--wait", lo->wait, "Slurm: wait until every job has left the queue");
  lau.add_option("--runner", lo->runner,
                 "Command of one run in place of this cradle's (`tma run`, `sami train`, `train`)");
  lau.callback([lo] { launch(*lo); });
}

// ---- generate: SaMI and BabyBench presets -------------------------------------------------

namespace {

struct GenerateOptions {
  std::string name, kind = "tma", out;
  TmaGenerateOptions tma;
  // SaMI.
  std::string methods, envs;
  int eval_episodes = 10;
  // BabyBench.
  std::string config, intrinsics, algo;
  // Shared: seeds (0: the kind's default) and steps (the kind's unit).
  int seeds = 0;
  double steps = 0;
  bool steps_given = false;
};

// A word of a generated line: no space, comment or control character.
void check_word(const std::string& flag, const std::string& value) {
  if (value.empty() || has_control(value) ||
      value.find_first_of(" \t#'\"\\") != std::string::npos) {
    throw UserError(flag + " '" + shown(value) +
                    "' (expected one word without spaces, quotes or #)");
  }
}

long run_steps(const GenerateOptions& o) {
  if (!(o.steps >= 1 && o.steps <= static_cast<double>(kMaxRunSteps)) ||
      o.steps != std::floor(o.steps)) {
    throw UserError("--steps " + number(o.steps) +
                    " (expected a whole number of env steps from 1 to " +
                    std::to_string(kMaxRunSteps) + ")");
  }
  return static_cast<long>(o.steps);
}

// SaMI's table: methods × envs × seeds, each seed evaluated on the three splits.
std::string generate_sami(const GenerateOptions& o) {
  std::vector<std::string> methods = {"TESAC", "CCM", "SaTESAC", "SaCCM"};
  if (!o.methods.empty()) methods = split_list(o.methods);
  std::vector<std::string> known_methods;
  for (const std::string_view m : learn::meta::method_names()) known_methods.emplace_back(m);
  for (const std::string& m : methods) {
    if (std::find(known_methods.begin(), known_methods.end(), m) == known_methods.end()) {
      throw UserError("--methods: '" + shown(m) + "' (expected some of: " + joined(known_methods) +
                      ")");
    }
  }
  const std::vector<std::string> all_envs = sami_env_names();
  std::vector<std::string> env_list = all_envs;
  if (!o.envs.empty()) env_list = split_list(o.envs);
  for (const std::string& e : env_list) {
    if (std::find(all_envs.begin(), all_envs.end(), e) == all_envs.end()) {
      throw UserError("--envs: '" + shown(e) + "' (expected some of: " + joined(all_envs) + ")");
    }
  }
  const int seeds = o.seeds > 0 ? o.seeds : 5;
  const std::string steps =
      o.steps_given ? " --steps-per-env " + std::to_string(run_steps(o)) : std::string();
  std::ostringstream f;
  f << "# cradle campaign: " << o.name << " (SaMI: " << joined(methods, " ") << " on "
    << joined(env_list, " ") << ", " << seeds << " seeds, "
    << (o.steps_given ? std::to_string(run_steps(o)) + " steps per env" : "each env's budget")
    << ", evaluated on train, moderate and extreme)\n"
    << "# Each line: --run sami --seeds N[+OFFSET] --name EXP [--campaign C] [--experiment E]\n"
    << "#   [--eval SPLITS --eval-episodes K] <cradle sami train args>. See docs/campaigns.md.\n";
  for (const std::string& env : env_list) {
    f << "## " << env << "\n";
    for (const std::string& m : methods) {
      f << "--run sami --seeds " << seeds << " --campaign " << o.name << " --experiment " << env
        << " --name " << o.name << "_" << env << "_" << m << " --env " << env << " --method " << m
        << steps << " --eval train,moderate,extreme --eval-episodes " << o.eval_episodes << "\n";
    }
  }
  return f.str();
}

// Which intrinsic rewards a config's env gives what they read (touch, eye images, hand-regard
// counters): each reward is bound to one env of the config, as a run binds it.
std::map<std::string, std::string> intrinsic_problems(const Config& config,
                                                      const std::vector<std::string>& names) {
  std::map<std::string, std::string> problems;
  std::unique_ptr<learn::ThreadedVecEnv> vec =
      train::make_babybench_vec_env(config, 1, 1, /*training=*/false, 0);
  for (const std::string& name : names) {
    try {
      learn::intrinsic::make_intrinsic(name)->bind(*vec);
    } catch (const std::exception& e) {
      problems[name] = e.what();
    }
  }
  return problems;
}

// BabyBench: intrinsic rewards × seeds on one config, and the no-intrinsic baseline.
std::string generate_babybench(const GenerateOptions& o) {
  if (o.config.empty()) throw UserError("--kind babybench needs --config FILE (a BabyBench YAML)");
  check_word("--config", fs::absolute(o.config).string());
  std::error_code ec;
  if (!fs::is_regular_file(o.config, ec)) {
    throw UserError("--config " + shown(o.config) + " is not a file (expected a BabyBench YAML)");
  }
  const Config config = load_config(o.config);
  const std::vector<std::string> registry = learn::intrinsic::intrinsic_names();
  std::vector<std::string> chosen;
  bool explicit_list = !o.intrinsics.empty();
  if (explicit_list) {
    chosen = split_list(o.intrinsics);
  } else {
    chosen = registry;
    chosen.insert(chosen.begin(), "none");
  }
  std::vector<std::string> names;  // the registry's among `chosen`
  for (const std::string& c : chosen) {
    if (c == "none") continue;
    if (std::find(registry.begin(), registry.end(), c) == registry.end()) {
      throw UserError("--intrinsics: '" + shown(c) +
                      "' (expected none or some of: " + joined(registry) + ")");
    }
    names.push_back(c);
  }
  std::set<std::string> seen;
  for (const std::string& c : chosen) {
    if (!seen.insert(c).second) throw UserError("--intrinsics: '" + c + "' is given twice");
  }
  if (!o.algo.empty()) {
    const std::vector<std::string> algos = learn::algorithm_names();
    if (std::find(algos.begin(), algos.end(), o.algo) == algos.end()) {
      throw UserError("--algo '" + shown(o.algo) + "' (expected one of: " + joined(algos) + ")");
    }
  }
  const std::map<std::string, std::string> problems = intrinsic_problems(config, names);
  if (explicit_list && !problems.empty()) {
    throw UserError("--intrinsics: " + problems.begin()->first + " does not fit " + o.config +
                    ": " + problems.begin()->second);
  }
  const int seeds = o.seeds > 0 ? o.seeds : 3;
  std::string common = "--config " + fs::absolute(o.config).string();
  if (!o.algo.empty()) common += " --algo " + o.algo;
  if (o.steps_given) common += " --steps " + std::to_string(run_steps(o));
  common += " --no-eval-video";
  const std::string behavior(behavior_name(config.behavior));
  std::ostringstream f;
  f << "# cradle campaign: " << o.name << " (BabyBench " << behavior << ": intrinsic rewards x "
    << seeds << " seeds on " << fs::absolute(o.config).string() << ")\n"
    << "# Each line: --run train --seeds N[+OFFSET] --name EXP [--campaign C] [--experiment E]\n"
    << "#   <cradle train args>; --intrinsic '' is no intrinsic reward. See docs/campaigns.md.\n";
  for (const std::string& c : chosen) {
    if (problems.count(c)) {
      f << "# " << c << " left out: " << problems.at(c) << "\n";
      continue;
    }
    f << "--run train --seeds " << seeds << " --campaign " << o.name << " --experiment " << behavior
      << " --name " << o.name << "_" << c << " " << common << " --intrinsic "
      << (c == "none" ? std::string("''") : c) << "\n";
  }
  return f.str();
}

std::string generate(const GenerateOptions& o, const CLI::App& gen) {
  if (!valid_name(o.name)) {
    throw UserError("campaign name '" + shown(o.name) + "' (" + kNameRule + ")");
  }
  // Each kind's own options; another kind's is an error, not silently ignored.
  const std::map<std::string, std::set<std::string>> own = {
      {"tma", {"--teacher", "--teacher-param", "--preset", "--test-episodes"}},
      {"sami", {"--methods", "--envs", "--eval-episodes"}},
      {"babybench", {"--config", "--intrinsics", "--algo"}}};
  if (!own.count(o.kind)) {
    throw UserError("--kind '" + shown(o.kind) + "' (expected tma, sami or babybench)");
  }
  for (const auto& [kind, flags] : own) {
    if (kind == o.kind) continue;
    for (const std::string& flag : flags) {
      if (gen.count(flag) > 0) {
        throw UserError(flag + " is for --kind " + kind + ", not --kind " + o.kind);
      }
    }
  }
  if (o.kind == "tma") {
    if (o.tma.teacher.empty()) throw UserError("--kind tma needs --teacher T");
    TmaGenerateOptions t = o.tma;
    t.name = o.name;
    t.seeds = o.seeds;
    t.steps = o.steps;
    t.steps_given = o.steps_given;
    return generate_tma(t);
  }
  if (o.kind == "sami") {
    if (o.eval_episodes < 1 || o.eval_episodes > 100000) {
      throw UserError("--eval-episodes " + std::to_string(o.eval_episodes) +
                      " (expected 1 to 100000)");
    }
    return generate_sami(o);
  }
  return generate_babybench(o);
}

}  // namespace

}  // namespace cradle::apps::campaign

namespace cradle::apps {

void register_campaign(CLI::App& app) {
  using namespace campaign;
  CLI::App* cmd = app.add_subcommand(
      "campaign", "Campaigns: one experiment's runs x seeds on Slurm or a local pool");
  cmd->require_subcommand(1);

  auto go = std::make_shared<GenerateOptions>();
  CLI::App* gen = cmd->add_subcommand(
      "generate",
      "Write a campaign file: TeachMyAgent's benchmark, SaMI's table or BabyBench's "
      "intrinsic rewards");
  gen->add_option("NAME", go->name, "Campaign name (prefix of every experiment)")->required();
  gen->add_option("--kind", go->kind, "tma | sami | babybench")->capture_default_str();
  gen->add_option("--seeds", go->seeds,
                  "Seeds per configuration (default: tma the preset's, sami 5, babybench 3)")
      ->check(CLI::Range(1, 100000))
      ->default_str("");
  gen->add_option("--steps", go->steps,
                  "tma: env steps per run in millions (default: the preset's); sami: env steps "
                  "per training env (default: the env's); babybench: env steps per run "
                  "(default: cradle train's)")
      ->default_str("");
  gen->add_option("--out", go->out, "Write here (default: stdout)");
  gen->add_option("--teacher", go->tma.teacher, "tma: teacher (Random, ADR, ALP-GMM, RIAC, ...)");
  gen->add_option("--teacher-param", go->tma.teacher_params, "tma: teacher parameter key=value");
  gen->add_option("--preset", go->tma.preset, "tma: paper | mini")->capture_default_str();
  gen->add_option("--test-episodes", go->tma.test_episodes,
                  "tma: 0: the reference's test sets; N: N default test tasks (default: the "
                  "preset's, paper 0, mini 10)")
      ->check(CLI::Range(0, 100000))
      ->default_str("");
  gen->add_option("--methods", go->methods,
                  "sami: methods, comma-separated (default: TESAC,CCM,SaTESAC,SaCCM)");
  gen->add_option("--envs", go->envs, "sami: envs, comma-separated (default: every SaMI env)");
  gen->add_option("--eval-episodes", go->eval_episodes, "sami: evaluation episodes per task cell")
      ->capture_default_str();
  gen->add_option("--config", go->config, "babybench: the BabyBench YAML config");
  gen->add_option("--intrinsics", go->intrinsics,
                  "babybench: intrinsic rewards, comma-separated, none for no intrinsic reward "
                  "(default: none and every registered reward the config's env can feed)");
  gen->add_option("--algo", go->algo, "babybench: learning algorithm (default: cradle train's)");
  gen->callback([go, gen] {
    go->steps_given = gen->count("--steps") > 0;
    const std::string text = generate(*go, *gen);
    if (go->out.empty()) {
      std::fputs(text.c_str(), stdout);
    } else {
      write_text(go->out, text);
      std::printf("wrote %s\n", go->out.c_str());
    }
  });

  auto lo = std::make_shared<LaunchOptions>();
  lo->results = "campaign_results";
  CLI::App* lau = cmd->add_subcommand("launch", "Run a campaign file (Slurm or locally)");
  add_launch_options(*lau, lo);

  struct AnalyzeOptions {
    std::string results, out, baseline;
  };
  auto ao = std::make_shared<AnalyzeOptions>();
  CLI::App* ana = cmd->add_subcommand(
      "analyze", "Tables (and TeachMyAgent's figures) of a results tree, by the kind of its runs");
  ana->add_option("RESULTS", ao->results, "Results tree of `campaign launch`")->required();
  ana->add_option("--out", ao->out, "Figures and tables folder (default RESULTS/analysis)");
  ana->add_option("--baseline", ao->baseline,
                  "TeachMyAgent: campaign compared against (default: the Random one)");
  ana->callback([ao] { analyze(ao->results, ao->out, ao->baseline); });
}

}  // namespace cradle::apps

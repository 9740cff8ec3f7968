// `cradle tma campaign generate|launch` and `cradle tma analyze`: TeachMyAgent's benchmark
// campaigns (many `cradle tma run` configurations × seeds) on Slurm or on a local process pool,
// and the paper's analysis of their results tree (python/cradle/tma_analysis.py).
//
// Campaign file (docs/tma_campaigns.md): one configuration per line, `#` starts a comment,
//   --seeds N[+OFFSET] --name EXP [--campaign C] [--experiment E] <cradle tma run arguments>
// runs seeds OFFSET..OFFSET+N-1 of `cradle tma run <arguments>`; an argument written `--*key v`
// is passed as `--key v` and appends `_key_v` to EXP (the reference's convention). Results tree:
//   RESULTS/EXP/EXP_s<seed>/   the run folder (+ launch.json: command, commit, line; log.txt)
//   RESULTS/EXP/launch/        the line, the commit and the sbatch script of each submission
// A seed is finished when its folder holds done.json (written by the run) or `finished` (written
// by the launcher after exit status 0).
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
#include "core/error.h"
#include "core/resources.h"
#include "envs/tma/tma_env.h"
#include "eval/video.h"
#include "learn/hyperparams.h"
#include "learn/registry.h"
#include "learn/vector_env.h"
#include "teach/registry.h"
#include "tma/render.h"

extern char** environ;

namespace cradle::apps {
namespace {

namespace fs = std::filesystem;

// One configuration of a campaign file.
struct CampaignLine {
  int line_no = 0;
  std::string text;                  // the line as written
  std::string name;                  // experiment folder name (starred arguments appended)
  std::string campaign, experiment;  // analysis labels
  int seeds = 0, offset = 0;         // seeds offset .. offset + seeds - 1
  std::vector<std::string> args;     // `cradle tma run` arguments, stars removed
};

// Arguments the launcher sets itself for every seed.
const std::set<std::string> kLauncherArgs = {"--seed", "--out", "--resume", "--exp_name"};

// Bounds of a campaign: seeds per line, the largest seed offset, runs per campaign file, env
// steps per run (millions), local jobs.
constexpr int kMaxSeeds = 100000;
constexpr int kMaxOffset = 1000000000;
constexpr long kMaxRuns = 1000000;
constexpr double kMinSteps = 1e-6, kMaxSteps = 1000;
constexpr int kMaxJobs = 4096;
constexpr size_t kMaxNameLength = 200;

// Names become folder names: letters, digits and _ - . + (no separators, spaces or shell
// characters), starting with a letter or a digit (so never ".", ".." or a hidden or flag-like
// folder), at most 200 characters.
bool valid_name(const std::string& s) {
  if (s.empty() || s.size() > kMaxNameLength || !std::isalnum(static_cast<unsigned char>(s[0])))
    return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' ||
           c == '+';
  });
}
const char* const kNameRule =
    "expected letters, digits, _ - . + starting with a letter or digit, at most 200 characters";

// A byte that would end or break a line of a campaign file or a script (newline, NUL, ...).
bool has_control(const std::string& s) {
  return std::any_of(s.begin(), s.end(), [](char c) {
    return std::iscntrl(static_cast<unsigned char>(c)) && c != '\t';
  });
}

// A value for error messages: control characters shown as \xNN, and cut after 60 characters.
std::string shown(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (out.size() >= 60) return out + "...";
    if (std::iscntrl(static_cast<unsigned char>(c))) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\x%02x", static_cast<unsigned char>(c));
      out += buf;
    } else {
      out += c;
    }
  }
  return out;
}

// A decimal integer in [min, max].
int parse_count(const std::string& text, const std::string& what, int min, int max) {
  const bool digits =
      !text.empty() && text.size() <= 10 && std::all_of(text.begin(), text.end(), [](char c) {
        return std::isdigit(static_cast<unsigned char>(c));
      });
  if (digits) {
    const long v = std::stol(text);
    if (v >= min && v <= max) return static_cast<int>(v);
  }
  throw UserError(what + " '" + shown(text) + "' (expected an integer from " + std::to_string(min) +
                  " to " + std::to_string(max) + ")");
}

// --steps / --nb_env_steps: env steps per run in millions.
void check_steps(double steps, const std::string& what) {
  if (!(steps >= kMinSteps && steps <= kMaxSteps)) {
    std::ostringstream s;
    s << what << " " << steps << " (expected millions of env steps from " << kMinSteps << " to "
      << kMaxSteps << ")";
    throw UserError(s.str());
  }
}

// A teacher parameter as `cradle tma run --teacher-param k=v` reads it: JSON when it parses, else
// a string.
nlohmann::json param_value(const std::string& v) {
  return nlohmann::json::accept(v) ? nlohmann::json::parse(v) : nlohmann::json(v);
}

// The teacher, its parameters and its expert knowledge, checked as the run will check them: the
// registry builds the teacher (on a unit 2-D task space), so an unknown name, an unknown key, a
// value of the wrong type or range, or an expert-knowledge level the teacher refuses is an error
// naming `where` now rather than in every seed's log later.
void check_teacher(const std::string& where, const std::string& teacher,
                   const std::vector<std::string>& params, const std::string& expert_knowledge) {
  teach::TeacherSetup setup;
  setup.name = teacher;
  setup.mins = {0, 0};
  setup.maxs = {1, 1};
  for (const std::string& p : params) {
    const size_t eq = p.find('=');
    if (eq == std::string::npos || eq == 0) {
      throw UserError(where + ": --teacher-param '" + shown(p) + "' (expected key=value)");
    }
    const std::string key = p.substr(0, eq);
    if (setup.params.contains(key)) {
      throw UserError(where + ": --teacher-param " + shown(key) +
                      " is given twice (expected each key once)");
    }
    setup.params[key] = param_value(p.substr(eq + 1));
  }
  // Built once per teacher, parameters and level (a campaign file repeats them on every line).
  static std::set<std::string> checked;
  const std::string key = teacher + "\n" + setup.params.dump() + "\n" + expert_knowledge;
  if (checked.count(key)) return;
  try {
    setup.expert_knowledge = teach::parse_expert_knowledge(expert_knowledge);
    teach::make_teacher(setup);
    checked.insert(key);
  } catch (const UserError& e) {
    throw UserError(where + ": " + e.what());
  }
}

std::vector<std::string> split_words(const std::string& text) {
  std::istringstream in(text);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

// One non-comment line -> a configuration; `where` names it in errors. The run's own arguments are
// passed as words (never through a shell unquoted); the teacher is checked through the registry.
CampaignLine parse_line(const std::string& text, const std::string& where) {
  if (has_control(text)) {
    throw UserError(where + ": a control character in '" + shown(text) +
                    "' (expected printable words)");
  }
  CampaignLine line;
  line.text = text;
  const std::vector<std::string> words = split_words(text);
  std::string suffix;
  bool has_seeds = false;
  // What the run will read as its teacher (`cradle tma run`'s defaults).
  std::string teacher = "ALP-GMM", expert_knowledge = "high";
  std::vector<std::string> teacher_params;
  for (size_t i = 0; i < words.size(); ++i) {
    const std::string& w = words[i];
    const bool has_value = i + 1 < words.size() && words[i + 1].rfind("--", 0) != 0;
    // Campaign keys: consumed here, never passed to the run.
    if (w == "--seeds" || w == "--name" || w == "--campaign" || w == "--experiment") {
      if (!has_value) throw UserError(where + ": " + w + " needs a value");
      const std::string& v = words[++i];
      std::string& label = w == "--name"       ? line.name
                           : w == "--campaign" ? line.campaign
                                               : line.experiment;
      if ((w == "--seeds" && has_seeds) || (w != "--seeds" && !label.empty())) {
        throw UserError(where + ": " + w + " is given twice (expected it once per line)");
      }
      if (w == "--seeds") {
        const size_t plus = v.find('+');
        line.seeds = parse_count(v.substr(0, plus), where + ": --seeds", 1, kMaxSeeds);
        if (plus != std::string::npos) {
          line.offset = parse_count(v.substr(plus + 1), where + ": --seeds offset", 0, kMaxOffset);
        }
        has_seeds = true;
      } else if (!valid_name(v)) {
        throw UserError(where + ": " + w + " '" + shown(v) + "' (" + kNameRule + ")");
      } else {
        label = v;
      }
      continue;
    }
    if (w.rfind("--", 0) != 0) {
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
    if (kLauncherArgs.count(flag)) {
      throw UserError(where + ": " + flag + " is set by the launcher for every seed (remove it)");
    }
    const bool valued = has_value || eq != std::string::npos;
    const std::string value = eq != std::string::npos ? inline_value
                              : has_value             ? words[i + 1]
                                                      : "";
    if (starred && (!valued || value.empty())) {
      throw UserError(where + ": " + w + " needs a value (--*key value appends _key_value to " +
                      "the name)");
    }
    if ((flag == "--teacher" || flag == "--allow_expert_knowledge" || flag == "--nb_env_steps" ||
         flag == "--teacher-param") &&
        !valued) {
      throw UserError(where + ": " + flag + " needs a value");
    }
    if (flag == "--teacher") teacher = value;
    if (flag == "--allow_expert_knowledge") expert_knowledge = value;
    if (flag == "--teacher-param") {
      // A vector option: every word up to the next flag.
      if (eq != std::string::npos) teacher_params.push_back(value);
      for (size_t j = i + 1;
           eq == std::string::npos && j < words.size() && words[j].rfind("--", 0) != 0; ++j) {
        teacher_params.push_back(words[j]);
      }
    }
    if (flag == "--nb_env_steps") {
      char* end = nullptr;
      const double steps = std::strtod(value.c_str(), &end);
      if (end == value.c_str() || *end != '\0') {
        throw UserError(where + ": --nb_env_steps '" + shown(value) +
                        "' (expected millions of env steps, a number)");
      }
      check_steps(steps, where + ": --nb_env_steps");
    }
    line.args.push_back(eq != std::string::npos && !starred ? w : flag);
    if (starred) {
      if (eq != std::string::npos) line.args.push_back(value);
      suffix += "_" + flag.substr(2) + "_" + value;
    }
  }
  if (!has_seeds) throw UserError(where + ": no --seeds N[+OFFSET]");
  if (line.name.empty()) throw UserError(where + ": no --name EXP");
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
  check_teacher(where, teacher, teacher_params, expert_knowledge);
  if (line.experiment.empty()) line.experiment = line.name;
  if (line.campaign.empty()) line.campaign = line.name;
  return line;
}

std::vector<CampaignLine> read_campaign(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw UserError("cannot read campaign file " + file.string());
  std::vector<CampaignLine> lines;
  std::set<std::string> names;
  std::string text;
  long runs = 0;
  for (int n = 1; std::getline(in, text); ++n) {
    if (!text.empty() && text.back() == '\r') text.pop_back();  // a CRLF file
    const size_t hash = text.find('#');
    const std::string body = text.substr(0, hash);
    const std::string where = file.string() + ":" + std::to_string(n);
    if (split_words(body).empty() && !has_control(body)) continue;
    CampaignLine line = parse_line(body, where);
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

// ---- generate ------------------------------------------------------------------------------

struct GenerateOptions {
  std::string name, teacher, preset = "paper", out;
  std::vector<std::string> teacher_params;
  bool steps_given = false;
  double steps = 0;        // millions; the preset's unless steps_given
  int seeds = 0;           // 0: the preset's
  int test_episodes = -1;  // 0: the named test sets (paper); N: N default test tasks; -1: preset's
};

// Teachers that refuse to run without expert knowledge (spec §1.3).
const std::set<std::string> kNeedExpertKnowledge = {"ADR", "GoalGAN", "Setter-Solver"};

std::string number(double v) {
  std::ostringstream s;
  s.precision(15);
  s << v;
  return s.str();
}

// Every configuration of both experiments for one teacher (spec §4.3, §5).
std::string generate(const GenerateOptions& o) {
  if (o.preset != "paper" && o.preset != "mini") {
    throw UserError("--preset '" + o.preset + "' (expected paper or mini)");
  }
  if (!valid_name(o.name)) {
    throw UserError("campaign name '" + shown(o.name) + "' (" + kNameRule + ")");
  }
  // Every teacher name is a folder-name word; the registry says which exist.
  const auto& teachers = teach::teacher_names();
  if (std::find(teachers.begin(), teachers.end(), o.teacher) == teachers.end()) {
    std::string valid;
    for (const std::string& t : teachers) valid += (valid.empty() ? "" : ", ") + t;
    throw UserError("--teacher '" + shown(o.teacher) + "' (expected one of: " + valid + ")");
  }
  // A parameter becomes one word of every line: no space, comment or control character.
  for (const std::string& p : o.teacher_params) {
    const size_t eq = p.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == p.size() || has_control(p) ||
        p.find_first_of(" \t#") != std::string::npos) {
      throw UserError("--teacher-param '" + shown(p) + "' (expected key=value without spaces)");
    }
  }
  if (o.steps_given) check_steps(o.steps, "--steps");
  const bool paper = o.preset == "paper";
  const double steps = o.steps_given ? o.steps : (paper ? 20.0 : 0.02);
  const int seeds = o.seeds > 0 ? o.seeds : (paper ? 16 : 2);
  const int test_episodes = o.test_episodes >= 0 ? o.test_episodes : (paper ? 0 : 10);
  // Paper: 40 evaluations (every 500 k steps at 20 M); mini: 2.
  const long test_every = std::max(1L, std::lround(steps * 1e6 / (paper ? 40 : 2)));
  const long periodical = std::max(1L, test_every / 2);
  const bool is_adr = o.teacher == "ADR";
  const bool is_random = o.teacher == "Random";

  std::string teacher_args = "--teacher " + o.teacher;
  for (const std::string& p : o.teacher_params) teacher_args += " --teacher-param " + p;
  const std::string budget = "--nb_env_steps " + number(steps) + " --test_every " +
                             std::to_string(test_every) + " --keep_periodical_task_samples " +
                             std::to_string(periodical);
  // The reference's test sets (100 tasks each), or N tasks of the default set (cheaper).
  const auto test_set = [&](const std::string& name) {
    return test_episodes == 0 ? "--test_set " + name
                              : "--nb_test_episodes " + std::to_string(test_episodes);
  };
  const std::string stumps = "--env stump-tracks " + test_set("parametric_stumps_test_set");

  std::ostringstream f;
  f << "# cradle tma campaign: " << o.name << " (teacher " << o.teacher << ", preset " << o.preset
    << ", " << number(steps) << " M steps, " << seeds << " seeds)\n"
    << "# Each line: --seeds N[+OFFSET] --name EXP [--campaign C] [--experiment E] <cradle tma "
       "run args>\n"
    << "# `--*key v` passes --key v and appends _key_v to EXP. See docs/tma_campaigns.md.\n";
  auto line = [&](int n, const std::string& offset, const std::string& experiment,
                  const std::string& args) {
    f << "--seeds " << n << offset << " --campaign " << o.name << " --experiment " << experiment
      << " --name " << o.name << "_" << experiment << " " << args << " " << teacher_args << " "
      << budget << "\n";
  };
  // Random's runs are duplicated into every EK level by the analysis: only its "none" block.
  std::vector<std::string> levels = {"none", "low", "high"};
  if (is_random) levels = {"none"};
  if (kNeedExpertKnowledge.count(o.teacher)) levels = {"low", "high"};
  // The parameters as the teacher reads them, at every expert-knowledge level written below.
  std::set<std::string> used_levels(levels.begin(), levels.end());
  used_levels.insert("low");  // Parkour
  for (const std::string& ek : used_levels) {
    check_teacher("--teacher-param", o.teacher, o.teacher_params, ek);
  }
  f << "#### Skill-specific comparison: Stump Tracks, criteria 1-5\n";
  for (const std::string& ek : levels) {
    const int n = is_adr ? 2 * seeds : seeds;
    const std::string bipedal = stumps + " --embodiment old_classic_bipedal --student sac";
    const std::string ek_arg = "--*allow_expert_knowledge " + ek;
    f << "## " << ek << " expert knowledge\n# Criterion 1: mostly unfeasible task space\n";
    line(n, "", "criterion_1", bipedal + " --max_stump_h 9 --max_obstacle_spacing 6 " + ek_arg);
    f << "# Criterion 2: mostly trivial task space\n";
    line(n, "", "criterion_2",
         bipedal + " --min_stump_h -3 --max_stump_h 3 --max_obstacle_spacing 6 " + ek_arg);
    f << "# Criterion 3: a student that forgets (reset every 7 M of 20 M steps)\n";
    line(n, "", "criterion_3",
         bipedal + " --max_stump_h 3 --max_obstacle_spacing 6 --reset_frequency " +
             std::to_string(std::lround(steps * 1e6 * 7 / 20)) + " " + ek_arg);
    f << "# Criterion 4: rugged difficulty (dimension shuffling)\n";
    line(n, "", "criterion_4",
         bipedal + " --max_stump_h 3 --max_obstacle_spacing 6 --shuffle_dimensions " + ek_arg);
    f << "# Criterion 5: a variety of students ({spider, small_bipedal} x {SAC, PPO})\n";
    const int n5 = is_adr && ek != "high" ? 2 * seeds : seeds;
    for (const char* student : {"sac", "ppo"}) {
      for (const char* body : {"spider", "small_bipedal"}) {
        line(n5, "", "criterion_5",
             stumps + " --max_stump_h 3 --max_obstacle_spacing 6 --*embodiment " + body +
                 " --*student " + student + (std::string(student) == "ppo" ? " --lr 0.0003" : "") +
                 " " + ek_arg);
      }
    }
  }
  f << "#### Global performance: Parkour, three embodiments with distinct seeds, low EK\n";
  const std::string parkour = "--env parkour --student sac --allow_expert_knowledge low";
  line(seeds, "", "parkour",
       parkour + " --*embodiment old_classic_bipedal " + test_set("walking_test_set_v1"));
  line(seeds, "+" + std::to_string(seeds), "parkour",
       parkour + " --*embodiment climbing_profile_chimpanzee " + test_set("climbing_test_set_v1"));
  line(seeds, "+" + std::to_string(2 * seeds), "parkour",
       parkour + " --*embodiment fish " + test_set("swimming_test_set_v1"));
  f << "#### Upper baseline: the plain [0, 3] x [0, 6] space\n";
  for (const std::string& ek : levels) {
    line(2 * seeds, "", "upper_baseline",
         stumps +
             " --embodiment old_classic_bipedal --student sac --max_stump_h 3 "
             "--max_obstacle_spacing 6 --*allow_expert_knowledge " +
             ek);
  }
  return f.str();
}

// ---- launch --------------------------------------------------------------------------------

struct LaunchOptions {
  std::string file, results = "tma_results", runner;
  std::vector<std::string> sbatch_args;
  int jobs = 1, seeds_per_job = 8;
  bool dry_run = false, resume = false, local = false, slurm = false, wait = false;
};

// One seed of one configuration.
struct SeedRun {
  const CampaignLine* line = nullptr;
  int seed = 0;
  fs::path dir;
};

// The run's own done.json or the launcher's marker after exit status 0.
bool finished(const fs::path& dir) {
  return fs::exists(dir / "done.json") || fs::exists(dir / "finished");
}

// A word for bash: as is when plain, else single-quoted.
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

bool on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  if (path == nullptr) return false;
  std::stringstream dirs(path);
  for (std::string d; std::getline(dirs, d, ':');) {
    if (!d.empty() && ::access((fs::path(d) / program).c_str(), X_OK) == 0) return true;
  }
  return false;
}

// The command that runs one seed of one run, without --seed/--out/--resume.
std::vector<std::string> run_prefix(const LaunchOptions& o, const CampaignLine& line) {
  std::vector<std::string> argv;
  if (o.runner.empty()) {
    argv = {fs::read_symlink("/proc/self/exe").string(), "tma", "run"};
  } else {
    argv = split_words(o.runner);
    if (argv.empty()) throw UserError("--runner is empty (expected a command)");
  }
  argv.insert(argv.end(), line.args.begin(), line.args.end());
  argv.push_back("--exp_name");
  argv.push_back(line.name);
  return argv;
}

std::vector<std::string> seed_command(const LaunchOptions& o, const SeedRun& r, bool resume) {
  std::vector<std::string> argv = run_prefix(o, *r.line);
  argv.insert(argv.end(), {"--seed", std::to_string(r.seed), "--out", r.dir.string()});
  if (resume) argv.push_back("--resume");
  return argv;
}

void write_text(const fs::path& file, const std::string& text) {
  std::ofstream out(file);
  out << text;
  if (!out) throw UserError("cannot write " + file.string());
}

// Records how a seed is run beside its results (the reference's copy of script and git log).
void write_launch_json(const LaunchOptions& o, const SeedRun& r, const std::string& commit) {
  fs::create_directories(r.dir);
  const nlohmann::json j = {{"campaign", r.line->campaign},
                            {"experiment", r.line->experiment},
                            {"name", r.line->name},
                            {"seed", r.seed},
                            {"args", r.line->args},
                            {"command", seed_command(o, r, false)},
                            {"commit", commit},
                            {"cradle_version", CRADLE_VERSION},
                            {"campaign_file", fs::absolute(o.file).string()},
                            {"campaign_line", r.line->line_no},
                            {"line", r.line->text}};
  write_text(r.dir / "launch.json", j.dump(1) + "\n");
}

// The finished marker (when the run wrote no done.json of its own).
void mark_finished(const fs::path& dir, double wall_s) {
  if (fs::exists(dir / "done.json")) return;
  write_text(dir / "finished",
             nlohmann::json{{"exit_status", 0}, {"wall_s", wall_s}}.dump() + "\n");
}

// Local process pool: at most `jobs` seeds at once, each logging to its folder's log.txt.
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
      const bool resume = fs::exists(r.dir / "run.json");
      const std::vector<std::string> argv = seed_command(o, r, resume);
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

// The sbatch script of one line: an array task runs `seeds_per_job` seeds, each pinned to one of
// the task's cores, and skips the seeds already finished.
std::string sbatch_script(const LaunchOptions& o, const CampaignLine& line,
                          const std::string& indices, const fs::path& exp_dir) {
  const int k = o.seeds_per_job;
  const std::string seed_dir = (exp_dir / (line.name + "_s")).string();
  std::ostringstream s;
  s << "#!/bin/bash\n"
    << "#SBATCH --job-name=" << line.name << "\n"
    << "#SBATCH --array=" << indices << "\n"
    << "#SBATCH --ntasks=1\n"
    << "#SBATCH --cpus-per-task=" << std::min(k, line.seeds) << "\n"
    << "#SBATCH --output=" << (exp_dir / "launch" / "slurm_%A_%a.out").string() << "\n";
  for (const std::string& a : o.sbatch_args) s << "#SBATCH " << a << "\n";
  s << "# " << line.name << ": seeds " << line.offset << ".." << line.offset + line.seeds - 1
    << ", " << k << " per array task (cradle tma campaign launch)\n"
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
    << "  [ -e \"$dir/done.json\" ] || [ -e \"$dir/finished\" ] && continue\n"
    << "  mkdir -p \"$dir\"\n"
    << "  resume=; [ -e \"$dir/run.json\" ] && resume=--resume\n"
    << "  cpu=${cpus[$((slot % ${#cpus[@]}))]}\n"
    << "  slot=$((slot + 1))\n"
    << "  (\n"
    << "    start=$(date +%s)\n"
    << "    taskset -c \"$cpu\" " << join_quoted(run_prefix(o, line))
    << " --seed \"$seed\" --out \"$dir\" $resume >> \"$dir/log.txt\" 2>&1 || exit $?\n"
    << "    [ -e \"$dir/done.json\" ] || echo \"{\\\"exit_status\\\": 0, \\\"wall_s\\\": "
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

int launch_slurm(const LaunchOptions& o, const std::vector<CampaignLine>& lines,
                 const std::vector<SeedRun>& runs, const std::string& commit) {
  std::vector<std::string> job_ids;
  // The array tasks of each line, in one pass over the runs (not one per line).
  std::map<const CampaignLine*, std::set<int>> blocks;
  for (const SeedRun& r : runs) {
    blocks[r.line].insert((r.seed - r.line->offset) / o.seeds_per_job);
  }
  for (const CampaignLine& line : lines) {
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
  for (const SeedRun& r : runs) ok += finished(r.dir) ? 1 : 0;
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

int launch(const LaunchOptions& o) {
  const bool slurm = o.slurm || (!o.local && on_path("sbatch"));
  check_launch_options(o, slurm);
  const std::vector<CampaignLine> lines = read_campaign(o.file);
  if (o.slurm && !o.dry_run && !on_path("sbatch")) {
    throw UserError("--slurm: sbatch is not on the PATH (start scripts/slurm-local.sh or drop it)");
  }
  // The seeds to run: every seed, less the finished ones under --resume.
  std::vector<SeedRun> runs;
  size_t skipped = 0;
  for (const CampaignLine& line : lines) {
    for (int s = line.offset; s < line.offset + line.seeds; ++s) {
      SeedRun r{&line, s, fs::path(o.results) / line.name / (line.name + "_s" + std::to_string(s))};
      if (fs::exists(r.dir) && !o.resume && !o.dry_run) {
        throw UserError(r.dir.string() + " exists (use --resume to continue the campaign)");
      }
      if (o.resume && finished(r.dir)) {
        ++skipped;
        continue;
      }
      runs.push_back(r);
    }
  }
  if (skipped) std::printf("--resume: %zu finished seeds skipped\n", skipped);
  const std::string commit = [] {
    const auto [ok, c] = capture("git -C " + quote(CRADLE_SOURCE_DIR) + " rev-parse HEAD");
    return ok && !c.empty() ? c : std::string("unknown");
  }();
  if (!o.dry_run) {
    for (const SeedRun& r : runs) write_launch_json(o, r, commit);
  }
  if (slurm) return launch_slurm(o, lines, runs, commit);
  if (o.dry_run) {
    for (const SeedRun& r : runs) {
      std::printf("%s\n", join_quoted(seed_command(o, r, fs::exists(r.dir / "run.json"))).c_str());
    }
    return 0;
  }
  return launch_local(o, runs);
}

// ---- analyze -------------------------------------------------------------------------------

int analyze(const std::string& results, const std::string& out, const std::string& baseline) {
  std::error_code ec;
  if (!fs::exists(results, ec)) {
    throw UserError("results folder " + results + " does not exist (expected a campaign's tree)");
  }
  if (!fs::is_directory(results, ec)) {
    throw UserError("results folder " + results + " is not a folder (expected a campaign's tree)");
  }
  const char* env_python = std::getenv("CRADLE_PYTHON");
  const std::string python = env_python && *env_python ? env_python : CRADLE_PYTHON;
  // An installed copy runs its own script, a build-tree binary the source tree's.
  const auto& installed = installed_resources();
  const std::string script = installed ? (*installed / "tma_analysis.py").string()
                                       : std::string(CRADLE_PYTHON_DIR) + "/cradle/tma_analysis.py";
  std::vector<std::string> argv = {python, script, results, "--out", out};
  if (!baseline.empty()) argv.insert(argv.end(), {"--baseline", baseline});
  std::vector<char*> cargv;
  for (const std::string& a : argv) cargv.push_back(const_cast<char*>(a.c_str()));
  cargv.push_back(nullptr);
  // The script's stderr comes through a pipe: its one-line error on bad input ("cradle: error:
  // ...", exit 1) becomes this command's own, so the user sees one line, not two.
  int err[2];
  if (::pipe2(err, O_CLOEXEC) != 0) throw UserError("cannot start " + python + ": no pipe");
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, err[1], STDERR_FILENO);
  pid_t pid = 0;
  const int spawned = posix_spawnp(&pid, python.c_str(), &actions, nullptr, cargv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  ::close(err[1]);
  if (spawned != 0) {
    ::close(err[0]);
    throw UserError("cannot start " + python +
                    " (expected Python 3 with matplotlib, scipy, pandas)");
  }
  // Relay the script's other stderr lines (warnings, a traceback) as they come.
  const std::string prefix = "cradle: error: ";
  std::string error, line;
  FILE* stream = ::fdopen(err[0], "r");
  for (int ch; (ch = std::fgetc(stream)) != EOF;) {
    line += static_cast<char>(ch);
    if (ch != '\n') continue;
    if (line.starts_with(prefix)) {
      error = line.substr(prefix.size(), line.size() - prefix.size() - 1);
    } else {
      std::fputs(line.c_str(), stderr);
    }
    line.clear();
  }
  if (!line.empty()) std::fputs(line.c_str(), stderr);
  std::fclose(stream);
  int status = 0;
  ::waitpid(pid, &status, 0);
  const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128;
  if (code != 0 && !error.empty()) throw UserError(error);
  if (code != 0)
    throw UserError("the analysis failed (" + script + " exit " + std::to_string(code) + ")");
  return 0;
}

// ---- video ---------------------------------------------------------------------------------

struct VideoOptions {
  std::string run, out;
  int test_task = 0, steps = 2000;
  std::uint64_t seed = 0;
  bool lidars = false;
};

// Row K of a run's test_set.csv as reset options (header task_index,<names...>).
envs::ResetOptions test_task(const fs::path& file, int k) {
  std::ifstream in(file);
  if (!in)
    throw UserError("cannot read " + file.string() + " (expected a `cradle tma run` folder)");
  std::string header, row;
  std::getline(in, header);
  std::vector<std::string> names;
  std::stringstream h(header);
  for (std::string n; std::getline(h, n, ',');) names.push_back(n);
  int rows = 0;
  while (std::getline(in, row)) {
    std::stringstream r(row);
    std::string cell;
    std::getline(r, cell, ',');
    if (cell != std::to_string(k)) {
      ++rows;
      continue;
    }
    envs::ResetOptions task;
    for (size_t i = 1; i < names.size() && std::getline(r, cell, ','); ++i) {
      task[names[i]] = std::stod(cell);
    }
    return task;
  }
  throw UserError("--test-task " + std::to_string(k) + " (expected 0.." + std::to_string(rows - 1) +
                  " of " + file.string() + ")");
}

// One deterministic episode of the run's latest checkpoint on test task K, rendered to a video.
void video(const VideoOptions& o) {
  const fs::path dir = o.run;
  std::ifstream run_file(dir / "run.json");
  if (!run_file) throw UserError("no run.json in " + dir.string() + " (expected a run folder)");
  nlohmann::json run;
  try {
    run = nlohmann::json::parse(run_file);
  } catch (const std::exception&) {
    throw UserError((dir / "run.json").string() + " is not JSON");
  }
  const nlohmann::json args = run.value("arguments", nlohmann::json::object());
  const std::string env_name = args.value("env", std::string("stump-tracks"));
  const std::string body = args.value("embodiment", std::string("old_classic_bipedal"));
  const envs::ResetOptions task = test_task(dir / "test_set.csv", o.test_task);
  const fs::path ckpt = dir / "checkpoints" / "latest.ckpt";
  if (!fs::exists(ckpt)) throw UserError("no checkpoint " + ckpt.string() + " (train first)");

  // The learner as saved (its own hyperparameters; no replay memory needed to act).
  const learn::CheckpointInfo info = learn::read_checkpoint_info(ckpt);
  learn::LearnerOptions lo;
  lo.hyperparameters = learn::parse_hyperparameter_text(info.config);
  if (lo.hyperparameters.count("buffer_size")) lo.hyperparameters["buffer_size"] = "1000";
  tma::TmaOptions options{
      .env = tma::parse_env_id(env_name), .body = body, .max_episode_steps = o.steps};
  // The run's body and Parkour options (`tma run --motors_torque ...`), as given.
  for (const auto& [name, value] : args.value("env_options", nlohmann::json::object()).items()) {
    tma::set_option(options, name, value.get<std::string>());
  }
  learn::ThreadedVecEnv vec(
      1, [&](int) { return std::make_unique<envs::TmaEnvAdapter>(options); }, 1);
  std::unique_ptr<learn::Learner> learner = learn::make_learner(info.algorithm, vec, lo);
  learner->load(ckpt);

  envs::TmaEnvAdapter env(options);
  env.set_reset_options(task);
  env.reset(o.seed);
  const std::string out =
      o.out.empty() ? (dir / ("test_task_" + std::to_string(o.test_task) + ".mp4")).string()
                    : o.out;
  const int w = 600, h = 400;
  eval::VideoWriter writer(out, w, h, tma::kFps);
  std::vector<std::uint8_t> frame;
  std::vector<double> action(env.action_space().size());
  double ret = 0;
  int length = 0;
  for (bool done = false; !done;) {
    tma::render(env.env(), w, h, o.lidars, frame);
    writer.write(frame);
    learner->act(env.observation(), action, /*deterministic=*/true);
    const envs::StepResult r = env.step(action);
    ret += r.reward;
    ++length;
    done = r.terminated || r.truncated;
  }
  tma::render(env.env(), w, h, o.lidars, frame);
  writer.write(frame);
  writer.close();
  std::printf("test task %d: return %.1f in %d steps (%s) after %ld training steps -> %s\n",
              o.test_task, ret, length, ret > 230 ? "mastered" : "not mastered", info.steps,
              out.c_str());
}

}  // namespace

void register_tma_campaign(CLI::App& tma) {
  CLI::App* campaign = tma.add_subcommand("campaign", "TeachMyAgent benchmark campaigns");
  campaign->require_subcommand(1);

  auto go = std::make_shared<GenerateOptions>();
  CLI::App* gen = campaign->add_subcommand("generate", "Write the campaign file of one teacher");
  gen->add_option("NAME", go->name, "Campaign name (prefix of every experiment)")->required();
  gen->add_option("--teacher", go->teacher, "Teacher (Random, ADR, ALP-GMM, RIAC, ...)")
      ->required();
  gen->add_option("--teacher-param", go->teacher_params, "Teacher parameter key=value");
  // Left out, these three take the preset's value: --help names it instead of the placeholder.
  gen->add_option("--test-episodes", go->test_episodes,
                  "0: the reference's test sets; N: N default test tasks (default: the "
                  "preset's, paper 0, mini 10)")
      ->check(CLI::Range(0, 100000))
      ->default_str("");
  gen->add_option("--steps", go->steps,
                  "Env steps per run, millions (default: the preset's, paper 20, mini 0.02)")
      ->default_str("");
  gen->add_option("--seeds", go->seeds,
                  "Seeds per configuration (default: the preset's, paper 16, mini 2)")
      ->check(CLI::Range(1, 100000))
      ->default_str("");
  gen->add_option("--preset", go->preset, "paper | mini");
  gen->add_option("--out", go->out, "Write here (default: stdout)");
  gen->callback([go, gen] {
    go->steps_given = gen->count("--steps") > 0;
    const std::string text = generate(*go);
    if (go->out.empty()) {
      std::fputs(text.c_str(), stdout);
    } else {
      write_text(go->out, text);
      std::printf("wrote %s\n", go->out.c_str());
    }
  });

  auto lo = std::make_shared<LaunchOptions>();
  CLI::App* lau = campaign->add_subcommand("launch", "Run a campaign file (Slurm or locally)");
  lau->add_option("FILE", lo->file, "Campaign file")->required();
  lau->add_option("--results", lo->results, "Results tree");
  lau->add_option("--jobs", lo->jobs, "Local: runs at once");
  lau->add_flag("--dry-run", lo->dry_run, "Print the sbatch scripts (or local commands) only");
  lau->add_flag("--resume", lo->resume, "Skip finished seeds, continue the others");
  lau->add_flag("--local", lo->local, "Local process pool even where sbatch exists");
  lau->add_flag("--slurm", lo->slurm, "Slurm (an error where sbatch is missing, but --dry-run)");
  lau->add_option("--seeds-per-job", lo->seeds_per_job, "Slurm: seeds per array task")
      ->check(CLI::Range(1, 1024));
  lau->add_option("--sbatch", lo->sbatch_args, "Slurm: extra #SBATCH line, e.g. --time=20:00:00");
  lau->add_flag("--wait", lo->wait, "Slurm: wait until every job has left the queue");
  lau->add_option("--runner", lo->runner, "Command of one run (default: this cradle's `tma run`)");
  lau->callback([lo] { launch(*lo); });

  struct AnalyzeOptions {
    std::string results, out, baseline;
  };
  auto ao = std::make_shared<AnalyzeOptions>();
  CLI::App* ana = tma.add_subcommand("analyze", "Figures, tests and tables of a results tree");
  ana->add_option("RESULTS", ao->results, "Results tree of `tma campaign launch`")->required();
  ana->add_option("--out", ao->out, "Figures and tables folder (default RESULTS/analysis)");
  ana->add_option("--baseline", ao->baseline,
                  "Campaign compared against (default: the Random one)");
  auto vo = std::make_shared<VideoOptions>();
  CLI::App* vid = tma.add_subcommand("video", "Render a trained policy on one test task");
  vid->add_option("--run", vo->run, "Run folder of `cradle tma run`")->required();
  vid->add_option("--test-task", vo->test_task, "Row of the run's test_set.csv")->required();
  vid->add_option("--out", vo->out, "Video file (.mp4 / .avi; default RUN/test_task_K.mp4)");
  vid->add_option("--steps", vo->steps, "Episode step cap")->check(CLI::Range(1, 100000));
  vid->add_option("--seed", vo->seed, "Seed of the episode");
  vid->add_flag("--lidars", vo->lidars, "Draw the lidar rays");
  vid->callback([vo] { video(*vo); });

  ana->callback([ao] {
    analyze(ao->results, ao->out.empty() ? (fs::path(ao->results) / "analysis").string() : ao->out,
            ao->baseline);
  });
}

}  // namespace cradle::apps

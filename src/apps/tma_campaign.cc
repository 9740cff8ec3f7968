// `cradle tma campaign generate|launch`, `cradle tma analyze` and `cradle tma video`:
// TeachMyAgent's spelling of the campaigns (src/apps/campaign.h, docs/campaigns.md). `generate`
// writes the paper's benchmark for one teacher (many `cradle tma run` configurations × seeds);
// `analyze` runs the paper's analysis of a results tree (python/cradle/tma_analysis.py); `video`
// renders a trained policy on one test task.
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
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
#include <vector>

#include "apps/campaign.h"
#include "apps/commands.h"
#include "core/error.h"
#include "core/resources.h"
#include "envs/tma/tma_env.h"
#include "eval/video.h"
#include "learn/hyperparams.h"
#include "learn/registry.h"
#include "learn/vector_env.h"
#include "teach/registry.h"
#include "tma/physics.h"
#include "tma/render.h"
#include "train/episodes.h"
#include "train/run_json.h"

extern char** environ;

namespace cradle::apps::campaign {

namespace fs = std::filesystem;

namespace {

// Teachers that refuse to run without expert knowledge (spec §1.3).
const std::set<std::string> kNeedExpertKnowledge = {"ADR", "GoalGAN", "Setter-Solver"};

}  // namespace

void check_steps(double steps, const std::string& what) {
  constexpr double kMinSteps = 1e-6, kMaxSteps = 1000;
  if (!(steps >= kMinSteps && steps <= kMaxSteps)) {
    std::ostringstream s;
    s << what << " " << steps << " (expected millions of env steps from " << kMinSteps << " to "
      << kMaxSteps << ")";
    throw UserError(s.str());
  }
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
  try {
    setup.params = teach::parse_teacher_params(params);
  } catch (const UserError& e) {
    throw UserError(where + ": " + e.what());
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

// Every configuration of both experiments for one teacher (spec §4.3, §5).
std::string generate_tma(const TmaGenerateOptions& o) {
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
    << "# `--*key v` passes --key v and appends _key_v to EXP. See docs/campaigns.md.\n";
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

// ---- analyze -------------------------------------------------------------------------------

int analyze_tma(const std::string& results, const std::string& out, const std::string& baseline) {
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

}  // namespace cradle::apps::campaign

namespace cradle::apps {
namespace {

namespace fs = std::filesystem;

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
  // The run's env, body and options, every key checked (a damaged run.json is one line).
  const train::RunJson run(dir / "run.json", "the run.json of a `cradle tma run` run");
  const train::RunJson args = run.object("arguments");
  const std::string env_name = args.string("env");
  const std::string body = args.string("embodiment");
  std::map<std::string, std::string> env_options;
  if (args.has("env_options")) env_options = args.string_map("env_options");
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
  for (const auto& [name, value] : env_options) tma::set_option(options, name, value);
  learn::ThreadedVecEnv vec(
      1, [&](int) { return std::make_unique<envs::TmaEnvAdapter>(options); }, 1);
  std::unique_ptr<learn::Learner> learner = learn::make_learner(info.algorithm, vec, lo);
  learner->load(ckpt);

  envs::TmaEnvAdapter env(options);
  env.set_reset_options(task);
  const std::string out =
      o.out.empty() ? (dir / ("test_task_" + std::to_string(o.test_task) + ".mp4")).string()
                    : o.out;
  const int w = 600, h = 400;
  eval::VideoWriter writer(out, w, h, tma::kFps);
  std::vector<std::uint8_t> frame;
  // The one evaluation rollout; a frame of the state each action sees, then of the last state.
  const std::uint64_t seed = o.seed;
  const train::EpisodeOutcome episode =
      train::run_episodes(
          env,
          {.act =
               [&](const envs::ObservationBuffers& observation, std::span<double> action) {
                 tma::render(env.env(), w, h, o.lidars, frame);
                 writer.write(frame);
                 learner->act(observation, action, /*deterministic=*/true);
               }},
          std::span(&seed, 1))
          .front();
  tma::render(env.env(), w, h, o.lidars, frame);
  writer.write(frame);
  writer.close();
  std::printf("test task %d: return %.1f in %d steps (%s) after %ld training steps -> %s\n",
              o.test_task, episode.episode_return, episode.length,
              episode.episode_return > tma::kSuccessReturn ? "mastered" : "not mastered",
              info.steps, out.c_str());
}

}  // namespace

void register_tma_campaign(CLI::App& tma) {
  CLI::App* campaign_cmd =
      tma.add_subcommand("campaign", "TeachMyAgent benchmark campaigns (also `cradle campaign`)");
  campaign_cmd->require_subcommand(1);

  auto go = std::make_shared<campaign::TmaGenerateOptions>();
  auto out = std::make_shared<std::string>();
  CLI::App* gen =
      campaign_cmd->add_subcommand("generate", "Write the campaign file of one teacher");
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
  gen->add_option("--out", *out, "Write here (default: stdout)");
  gen->callback([go, gen, out] {
    go->steps_given = gen->count("--steps") > 0;
    const std::string text = campaign::generate_tma(*go);
    if (out->empty()) {
      std::fputs(text.c_str(), stdout);
    } else {
      campaign::write_text(*out, text);
      std::printf("wrote %s\n", out->c_str());
    }
  });

  auto lo = std::make_shared<campaign::LaunchOptions>();
  lo->results = "tma_results";
  CLI::App* lau = campaign_cmd->add_subcommand("launch", "Run a campaign file (Slurm or locally)");
  campaign::add_launch_options(*lau, lo);

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
    campaign::analyze_tma(ao->results,
                          ao->out.empty() ? (fs::path(ao->results) / "analysis").string() : ao->out,
                          ao->baseline);
  });
}

}  // namespace cradle::apps

#include "train/sami/sami_train.h"

#include <torch/torch.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <numeric>
#include <sstream>

#include "core/config.h"
#include "core/error.h"
#include "core/sealed_file.h"
#include "envs/registry.h"
#include "envs/sami/sami_env.h"
#include "eval/video.h"
#include "learn/checkpoint.h"
#include "learn/hyperparams.h"
#include "learn/meta/context_sac.h"
#include "learn/meta/sami_learner.h"
#include "learn/registry.h"
#include "sami/env.h"
#include "sami/render.h"
#include "sami/task.h"
#include "train/env_vector.h"
#include "train/episodes.h"
#include "train/loop.h"
#include "train/run_json.h"
#include "train/trainer.h"

namespace cradle::train {
namespace {

namespace fs = std::filesystem;

// The learner registry's name of a SaMI method ("SaCCM" -> "saccm"); UserError for another.
std::string learner_name(const std::string& method) {
  for (const std::string_view name : learn::meta::sami_learner_names()) {
    if (learn::meta::sami_method(name) == method) return std::string(name);
  }
  learn::meta::method_contrast(method);  // the one-line error naming the methods
  throw UserError("unknown SaMI method '" + method + "'");
}

// Whether `run` holds a run: a checkpoint (this layout's or an earlier one's) or progress rows.
fs::path held_run(const fs::path& run) {
  std::error_code ec;
  for (const fs::path& file : {run / "checkpoints" / "latest.ckpt", run / "checkpoint.ckpt"}) {
    if (fs::exists(file, ec)) return file;
  }
  std::ifstream in(run / "logs" / "progress.csv");
  std::string line;
  if (std::getline(in, line) && std::getline(in, line) && !line.empty())
    return run / "logs" / "progress.csv";
  return {};
}

std::string cell_name(const sami::TaskSet& set, bool panda) {
  std::ostringstream s;
  if (panda && !set.cells.empty()) {
    s << "friction " << set.cells[0][0] << ", mass " << set.cells[0][1];
    return s.str();
  }
  const auto list = [&](const std::vector<double>& v) {
    std::string out;
    for (double x : v) out += (out.empty() ? "" : " ") + csv_cell(x);
    return out;
  };
  s << "mass {" << list(set.mass) << "} damping {" << list(set.damping) << "}";
  if (!set.cripple.empty()) {
    s << " cripple";
    for (const auto& c : set.cripple) s << " [" << sami::joints_text(c, ",") << "]";
  }
  return s.str();
}

}  // namespace

std::vector<sami::TaskSet> sami_training_sets(sami::EnvId id) {
  return sami::one_set_per_env(sami::split_sets(id, sami::Split::kTrain));
}

std::map<std::string, std::string> sami_presets(const std::string& env_id, int max_episode_steps,
                                                const std::string& algorithm) {
  if (learn::meta::sami_method(algorithm).empty()) return {};
  std::map<std::string, std::string> presets;
  if (max_episode_steps > 0) {
    presets["horizon"] = std::to_string(max_episode_steps);
    presets["report_every"] = std::to_string(max_episode_steps);
  }
  // Panda's config (tma_sami.md §6).
  if (env_id.starts_with("sami/PandaPush:")) {
    presets["buffer_size"] = "1000";
    presets["batch_size"] = "256";
    presets["contrast_batch_size"] = "256";
  }
  return presets;
}

SamiRunFile read_sami_run(const fs::path& run) {
  const RunJson j(run / "run.json", "the run.json of a `cradle sami train` run");
  if (!j.has("algorithm") && j.has("method") && j.has("steps_per_env")) {
    throw UserError(j.where() +
                    " is an earlier `cradle sami train` run (checkpoint.ckpt beside progress.csv), "
                    "which this version does not read: train it again into a new folder");
  }
  SamiRunFile r{.env_id = j.string("env"),
                .algorithm = j.string("algorithm"),
                .seed = j.unsigned_integer("seed"),
                .envs = j.positive_integer("envs"),
                .hyperparameters = j.string_map("hyperparameters")};
  r.steps = j.positive_integer("steps");
  const std::string family = j.string("family");
  // A run of another family or learner names the file it came from.
  if (family != "sami" || !r.env_id.starts_with("sami/")) {
    throw UserError(j.where() + ": env '" + r.env_id + "' is not a SaMI env (expected sami/<Env>)");
  }
  r.method = std::string(learn::meta::sami_method(r.algorithm));
  if (r.method.empty()) {
    throw UserError(j.where() + ": algorithm '" + r.algorithm +
                    "' is not one of SaMI's learners (expected tesac, ccm, satesac, saccm or "
                    "saccm_all)");
  }
  r.env = envs::split_env_id(r.env_id).name;
  try {
    sami::env_from_name(r.env);
  } catch (const UserError& e) {
    throw UserError(j.where() + ": " + e.what());
  }
  r.steps_per_env = (r.steps + r.envs - 1) / r.envs;
  return r;
}

SamiTrainResult sami_train(const SamiTrainOptions& options) {
  // The run's settings: fresh from the options, or on --resume from run.json.
  if (options.out.empty() && (options.env.empty() || options.method.empty())) {
    throw UserError("sami train: give the run folder (--out) or the env and the method");
  }
  if (options.resume && options.overwrite)
    throw UserError("sami train: --resume and --overwrite: give one of them");
  const fs::path run = options.out.empty()
                           ? fs::path("runs/sami") / (options.env + "_" + options.method + "_" +
                                                      std::to_string(options.seed))
                           : options.out;
  std::string env_name = options.env, method = options.method;
  std::uint64_t seed = options.seed;
  long steps_per_env = options.steps_per_env;
  // What the folder holds already (a fresh run refuses it without --overwrite, which clears it).
  const fs::path held = options.resume ? fs::path() : held_run(run);
  if (options.resume) {
    const SamiRunFile saved = read_sami_run(run);
    // A resumed run keeps its env and method: one given that contradicts them is refused, not
    // ignored.
    const auto keep = [&](const std::string& given, const std::string& kept, const char* flag) {
      if (!given.empty() && given != kept) {
        throw UserError("sami train --resume: " + (run / "run.json").string() + " is a run of " +
                        flag + " " + kept + ", not " + flag + " " + given + " (leave " + flag +
                        " out to continue it)");
      }
    };
    keep(options.env, saved.env, "--env");
    keep(options.method, saved.method, "--method");
    // A `cradle train` run on another split or vector continues there, not on SaMI's sets.
    const std::string ours = "sami/" + saved.env + ":train";
    if (saved.env_id != ours ||
        saved.envs !=
            static_cast<long>(sami_training_sets(sami::env_from_name(saved.env)).size())) {
      throw UserError("sami train --resume: " + (run / "run.json").string() + " is a run of " +
                      saved.env_id + " on " + std::to_string(saved.envs) +
                      " envs, not of SaMI's training sets: continue it with `cradle train --env " +
                      saved.env_id + " --save-dir " + run.string() + " --resume`");
    }
    env_name = saved.env;
    method = saved.method;
    seed = saved.seed;
    if (steps_per_env == 0) steps_per_env = saved.steps_per_env;
  } else if (!held.empty() && !options.overwrite) {
    throw UserError("sami train: " + run.string() + " already holds a run (" + held.string() +
                    "): pass --resume to continue it, --overwrite to replace it, or another --out");
  }
  if (options.steps < 0) throw UserError("sami train: --steps must be positive");
  const sami::EnvId id = sami::env_from_name(env_name);
  const std::string algorithm = learner_name(method);
  const long envs = static_cast<long>(sami_training_sets(id).size());
  if (options.steps > 0) steps_per_env = (options.steps + envs - 1) / envs;
  if (steps_per_env == 0) steps_per_env = id == sami::EnvId::kPandaPush ? 1'000'000 : 500'000;
  if (steps_per_env < 0) throw UserError("sami train: --steps-per-env must be positive");
  if (options.checkpoint_every < 1)
    throw UserError("sami train: checkpoint_every must be positive");
  if (options.report_every < 0) throw UserError("sami train: report_every must be positive");

  // SaMI's settings come with `cradle train`'s presets for its learners (sami_presets); a
  // resumed run keeps its checkpoint's. The user's go over them.
  std::map<std::string, std::string> hp;
  if (options.report_every > 0) hp["report_every"] = std::to_string(options.report_every);
  for (const auto& [k, v] : options.hyperparameters) hp[k] = v;

  // An overwritten run's evaluations go with it (`cradle train` removes its logs and
  // checkpoints, and an earlier layout's files go here).
  if (options.overwrite && !held.empty()) {
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(run, ec)) {
      const std::string name = entry.path().filename().string();
      if (name.starts_with("checkpoint.ckpt") || name.starts_with("progress.") ||
          name.starts_with("eval_") || name.starts_with("contexts_")) {
        fs::remove_all(entry.path(), ec);
      }
    }
  }

  Config config;
  config.save_dir = run.string();
  SamiTrainResult result{.run = run, .checkpoint = run / "checkpoints" / "final.ckpt"};
  long window_updates = 0;
  double update_seconds = 0;
  const TrainResult trained =
      train(config, {.env = "sami/" + env_name + ":train",
                     .algorithm = algorithm,
                     .intrinsic = "",
                     .steps = steps_per_env * envs,
                     .envs = static_cast<int>(envs),
                     .threads = 1,  // SaMI's envs step one after the other (its DummyVecEnv)
                     .seed = seed,
                     .resume = options.resume,
                     .overwrite = options.overwrite,
                     .checkpoint_every = options.checkpoint_every * envs,
                     .hyperparameters = hp,
                     .eval_episodes = 0,
                     .progress_bar = options.progress_bar,
                     .stop = options.stop,
                     .on_report =
                         [&](const learn::TrainStats& s) {
                           const auto loss = [&](const char* key) {
                             const auto it = s.losses.find(key);
                             return it == s.losses.end() ? 0.0 : it->second;
                           };
                           result.updates = static_cast<long>(loss("updates"));
                           window_updates += static_cast<long>(loss("gradient_steps"));
                           update_seconds += loss("update_seconds");
                           if (s.episodes > 0) result.last_return = s.episodic_return;
                         },
                     .sync = options.sync});
  result.steps = trained.steps;
  result.parameter_hash = trained.parameter_hash;
  result.sps = trained.steps_per_second;
  result.gradient_steps_per_s = update_seconds > 0 ? window_updates / update_seconds : 0;
  result.stopped = options.stop && options.stop->load() && result.steps < steps_per_env * envs;
  return result;
}

SamiEvalResult sami_evaluate(const SamiEvalOptions& options) {
  const SamiRunFile saved = read_sami_run(options.run);
  const sami::EnvId id = sami::env_from_name(saved.env);
  const std::string method = saved.method;
  const sami::Split split = sami::split_from_name(options.split);
  if (options.episodes < 1) throw UserError("sami evaluate: --episodes must be positive");
  const sami::Spec spec = sami::env_spec(id);
  const bool panda = id == sami::EnvId::kPandaPush;
  // The trained learner, on a vector of the run's training envs (its spaces and replay shape).
  const fs::path checkpoint = options.run / "checkpoints" / "latest.ckpt";
  std::error_code ec;
  if (!fs::exists(checkpoint, ec)) {
    throw UserError("sami evaluate: no checkpoint at '" + checkpoint.string() +
                    "' (train the run first: cradle sami train --out " + options.run.string() +
                    ")");
  }
  const learn::CheckpointInfo info = learn::read_checkpoint_info(checkpoint);
  const std::map<std::string, std::string> settings = learn::parse_hyperparameter_text(info.config);
  const auto context_setting = settings.find("context_size");
  if (info.algorithm != saved.algorithm || context_setting == settings.end()) {
    throw UserError("sami evaluate: " + checkpoint.string() + " is not the " + saved.algorithm +
                    " checkpoint its run.json names");
  }
  const int context_size = std::stoi(context_setting->second);
  std::unique_ptr<learn::VecEnv> vec =
      make_env_training(saved.env_id, static_cast<int>(saved.envs), 1, 0, {}, 0).vec;
  std::unique_ptr<learn::Learner> learner =
      learn::make_learner(info.algorithm, *vec, {.hyperparameters = settings});
  learner->load(checkpoint);
  torch::set_num_threads(1);

  SamiEvalResult result{.split = options.split, .skills = panda};
  const std::string stem = "eval_" + options.split;
  result.json = options.run / (stem + ".json");
  result.csv = options.run / (stem + ".csv");
  result.contexts = options.run / ("contexts_" + options.split + ".csv");
  std::ofstream contexts(result.contexts);
  contexts << "task_set,cell,episode,step,mass,damping,crippled,skill,episode_skill";
  for (int k = 0; k < context_size; ++k) contexts << ",c" << k;
  contexts << ",pc1,pc2\n";
  std::vector<std::string> context_rows, episode_rows;
  std::vector<float> context_values;
  std::unique_ptr<eval::VideoWriter> video;
  std::vector<std::uint8_t> frame;

  const std::vector<sami::TaskSet> sets = sami::split_sets(id, split);
  double all_success = 0, all_return = 0;
  int all_episodes = 0;
  // Every step of Panda's 50-step episodes; every 10th of the long locomotion ones.
  const int context_every = panda ? 1 : 10;
  for (size_t s = 0; s < sets.size(); ++s) {
    envs::SamiEnvAdapter adapter(sami::make_env(id, {sets[s]}, options.seed + s));
    sami::SamiEnv& env = adapter.sami();
    std::unique_ptr<sami::Renderer> renderer;
    if (options.video) {
      renderer = std::make_unique<sami::Renderer>(env, 320, 240);
      frame.resize(320 * 240 * 3);
      if (!video) {
        video = std::make_unique<eval::VideoWriter>(options.run / (stem + ".mp4"), 320, 240,
                                                    1.0 / spec.dt);
      }
    }
    SamiCell cell{.name = cell_name(sets[s], panda)};
    // The cell's episodes through the one rollout, each going on with the env's own stream. After
    // every step: the context the learner acted with and the step's task and skill (every
    // context_every-th step), the first episode's frame; at the episode's end its skill labels
    // the rows and counts in the cell's mix.
    learn::Learner* l = learner.get();
    std::string episode_task;
    const std::vector<EpisodeOutcome> episodes = run_episodes(
        adapter,
        {.act = [l](const envs::ObservationBuffers& obs,
                    std::span<double> a) { l->act(obs, a, /*deterministic=*/true); },
         .new_episode = [l] { l->new_episode(); }},
        options.episodes, 0, [&](int e, const envs::Env&, const envs::StepResult& r) {
          const sami::Info& info = env.info();
          const int step = info.steps - 1;
          // The parameters this episode drew (the task, within its task set): mass, damping, the
          // crippled joints ("0+4"; "none").
          if (step == 0) {
            episode_task = csv_cell(info.mass) + "," + csv_cell(info.damping) + "," +
                           (info.crippled.empty() ? "none" : sami::joints_text(info.crippled, "+"));
          }
          if (step % context_every == 0) {
            const std::span<const float> c = learn::meta::last_context(*l);
            episode_rows.push_back(std::to_string(s) + ",\"" + cell.name + "\"," +
                                   std::to_string(e) + "," + std::to_string(step) + "," +
                                   episode_task + "," + std::string(sami::skill_name(info.skill)));
            context_values.insert(context_values.end(), c.begin(), c.end());
          }
          if (renderer && e == 0) {
            renderer->render(env, frame);
            video->write(frame);
          }
          if (!r.terminated && !r.truncated) return;
          const std::string episode_skill(sami::skill_name(info.episode_skill));
          for (std::string& row : episode_rows) context_rows.push_back(row + "," + episode_skill);
          episode_rows.clear();
          cell.success_rate += info.is_success;
          cell.push += info.episode_skill == sami::Skill::kPush;
          cell.roll += info.episode_skill == sami::Skill::kRoll;
          cell.pick_and_place += info.episode_skill == sami::Skill::kPickAndPlace;
        });
    std::vector<double> episode_returns;
    for (const EpisodeOutcome& o : episodes) episode_returns.push_back(o.episode_return);
    cell.episodes = options.episodes;
    const double k = options.episodes;
    all_success += cell.success_rate;
    all_episodes += options.episodes;
    cell.success_rate /= k;
    cell.push /= k;
    cell.roll /= k;
    cell.pick_and_place /= k;
    cell.mean_return = std::accumulate(episode_returns.begin(), episode_returns.end(), 0.0) / k;
    all_return += cell.mean_return * k;
    double var = 0;
    for (double v : episode_returns) var += (v - cell.mean_return) * (v - cell.mean_return);
    cell.std_return = std::sqrt(var / k);
    result.cells.push_back(cell);
  }
  if (video) video->close();
  result.success_rate = all_success / all_episodes;
  result.mean_return = all_return / all_episodes;

  // Context pictures: the 2-D PCA of every recorded context (centred, top two right singular
  // vectors).
  const long rows = static_cast<long>(context_rows.size());
  torch::Tensor pcs = torch::zeros({rows, 2});
  if (rows > 1) {
    const torch::Tensor x =
        torch::from_blob(context_values.data(), {rows, context_size}).to(torch::kFloat64);
    const torch::Tensor centred = x - x.mean(0, true);
    // torch::svd (LibTorch's linalg_svd, V untransposed): copying linalg::svd's empty driver
    // optional is a -Wmaybe-uninitialized error of GCC 12 in the -O1 sanitizer build.
    const auto [u, sv, v] = torch::svd(centred, /*some=*/true);
    pcs = torch::matmul(centred, v.narrow(1, 0, std::min<long>(2, v.size(1))));
    if (pcs.size(1) < 2) pcs = torch::cat({pcs, torch::zeros({rows, 1}, torch::kFloat64)}, 1);
  }
  const torch::Tensor pc = pcs.to(torch::kFloat64).contiguous();
  for (long r = 0; r < rows; ++r) {
    contexts << context_rows[r];
    for (int k = 0; k < context_size; ++k) {
      contexts << "," << csv_cell(context_values[r * context_size + k]);
    }
    contexts << "," << csv_cell(pc[r][0].item<double>()) << "," << csv_cell(pc[r][1].item<double>())
             << "\n";
  }

  // Per-cell CSV and JSON.
  std::ostringstream table;
  table << "cell,episodes,success_rate,mean_return,std_return,push,roll,pick_and_place\n";
  nlohmann::json json{{"env", saved.env},
                      {"method", method},
                      {"seed", saved.seed},
                      {"split", options.split},
                      {"episodes_per_cell", options.episodes},
                      {"success_rate", result.success_rate},
                      {"mean_return", result.mean_return},
                      {"cells", nlohmann::json::array()}};
  for (const SamiCell& c : result.cells) {
    table << "\"" << c.name << "\"," << c.episodes << "," << csv_cell(c.success_rate) << ","
          << csv_cell(c.mean_return) << "," << csv_cell(c.std_return) << "," << csv_cell(c.push)
          << "," << csv_cell(c.roll) << "," << csv_cell(c.pick_and_place) << "\n";
    json["cells"].push_back({{"cell", c.name},
                             {"episodes", c.episodes},
                             {"success_rate", c.success_rate},
                             {"mean_return", c.mean_return},
                             {"std_return", c.std_return},
                             {"push", c.push},
                             {"roll", c.roll},
                             {"pick_and_place", c.pick_and_place}});
  }
  write_atomically(result.csv, table.str());
  write_atomically(result.json, json.dump(2) + "\n");
  return result;
}

}  // namespace cradle::train

#include "train/sami/sami_train.h"

#include <torch/torch.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <numeric>
#include <sstream>

#include "core/error.h"
#include "core/folders.h"
#include "core/sealed_file.h"
#include "eval/video.h"
#include "learn/checkpoint.h"
#include "learn/meta/context_sac.h"
#include "learn/run_files.h"
#include "sami/env.h"
#include "sami/render.h"
#include "sami/task.h"
#include "sami/vector.h"
#include "train/loop.h"
#include "train/run_json.h"

namespace cradle::train {
namespace {

using Clock = std::chrono::steady_clock;
using learn::meta::ContextSac;
using learn::meta::SamiConfig;
using learn::meta::TrajectoryReplay;

constexpr const char* kProgressHeader =
    "steps,episodes,return,success_rate,critic_loss,actor_loss,alpha,entropy,sance_loss,"
    "sance_weight,sps,gradient_steps_per_s,updates";

double seconds(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

// SaMI's per-env budget and the Panda config's batch sizes (tma_sami.md §6), before user values.
std::map<std::string, std::string> env_defaults(sami::EnvId id) {
  if (id != sami::EnvId::kPandaPush) return {};
  return {{"buffer_size", "1000"}, {"batch_size", "256"}, {"contrast_batch_size", "256"}};
}

SamiConfig make_config(sami::EnvId id, const std::map<std::string, std::string>& user,
                       std::string& text) {
  std::map<std::string, std::string> all = env_defaults(id);
  for (const auto& [k, v] : user) all[k] = v;
  SamiConfig config;
  text = learn::meta::apply_sami_hyperparameters(config, all);
  return config;
}

std::vector<float> to_vector(std::span<const float> x) { return {x.begin(), x.end()}; }

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

SamiRunFile read_sami_run(const std::filesystem::path& run) {
  const RunJson j(run / "run.json", "the run.json of a `cradle sami train` run");
  SamiRunFile r{.env = j.string("env"),
                .method = j.string("method"),
                .seed = j.unsigned_integer("seed"),
                .steps_per_env = j.positive_integer("steps_per_env"),
                .hyperparameters = j.string_map("hyperparameters")};
  // An unknown env or method names the file it came from.
  try {
    sami::env_from_name(r.env);
    learn::meta::method_contrast(r.method);
  } catch (const UserError& e) {
    throw UserError(j.where() + ": " + e.what());
  }
  return r;
}

SamiTrainResult sami_train(const SamiTrainOptions& options) {
  // The run's settings: fresh from the options, or on --resume from run.json.
  if (options.out.empty() && (options.env.empty() || options.method.empty())) {
    throw UserError("sami train: give the run folder (--out) or the env and the method");
  }
  const std::filesystem::path run =
      options.out.empty()
          ? std::filesystem::path("runs/sami") /
                (options.env + "_" + options.method + "_" + std::to_string(options.seed))
          : options.out;
  std::string env_name = options.env, method = options.method;
  std::uint64_t seed = options.seed;
  long steps_per_env = options.steps_per_env;
  std::map<std::string, std::string> hp = options.hyperparameters;
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
    env_name = saved.env;
    method = saved.method;
    seed = saved.seed;
    if (steps_per_env == 0) steps_per_env = saved.steps_per_env;
    std::map<std::string, std::string> merged = saved.hyperparameters;
    for (const auto& [k, v] : hp) merged[k] = v;
    hp = merged;
  } else if (std::filesystem::exists(run / "checkpoint.ckpt") && !options.overwrite) {
    throw UserError("sami train: " + run.string() +
                    " already holds a run: pass --resume to continue it, --overwrite to replace "
                    "it, or another --out");
  }
  if (options.resume && options.overwrite)
    throw UserError("sami train: --resume and --overwrite: give one of them");
  if (options.steps < 0) throw UserError("sami train: --steps must be positive");
  const sami::EnvId id = sami::env_from_name(env_name);
  learn::meta::method_contrast(method);  // UserError for an unknown method
  if (options.steps > 0) {
    const long envs = static_cast<long>(sami_training_sets(id).size());
    steps_per_env = (options.steps + envs - 1) / envs;
  }
  if (steps_per_env == 0) steps_per_env = id == sami::EnvId::kPandaPush ? 1'000'000 : 500'000;
  if (steps_per_env < 0) throw UserError("sami train: --steps-per-env must be positive");
  if (options.checkpoint_every < 1)
    throw UserError("sami train: checkpoint_every must be positive");
  std::string config_text;
  const SamiConfig config = make_config(id, hp, config_text);
  // One LibTorch thread while acting (tiny matrices; a second thread only waits), as the other
  // learners' torch_threads = 1; updates use update_threads.
  torch::set_num_threads(1);

  // The training envs (one per task set) and the learner.
  const std::vector<sami::TaskSet> sets = sami_training_sets(id);
  sami::SamiVector envs(id, sets, seed, /*threads=*/1);
  const sami::Spec& spec = envs.spec();
  const int n = envs.size();
  if (learn::meta::method_contrast(method) == learn::meta::Contrast::kEnvDiff && n < 2) {
    throw UserError("sami train: " + method + " contrasts training envs and needs at least 2");
  }
  ContextSac learner(method, spec.obs_size, spec.action_size, config, seed);
  TrajectoryReplay replay(n, config.buffer_size, spec.horizon, spec.obs_size, spec.action_size);
  Rng rng(seed ^ 0x5a4d49ULL);
  {
    std::error_code ec;
    if (options.overwrite) {
      // The files a run and its evaluations write; anything else in the folder stays.
      for (const auto& entry : std::filesystem::directory_iterator(run, ec)) {
        const std::string name = entry.path().filename().string();
        if (name == "run.json" || name == "progress.csv" || name.starts_with("checkpoint.ckpt") ||
            name.starts_with("progress.") || name.starts_with("eval_") ||
            name.starts_with("contexts_")) {
          std::filesystem::remove_all(entry.path(), ec);
        }
      }
    }
    make_folder(run, "sami train: cannot create the run folder");
  }
  const std::filesystem::path checkpoint = run / "checkpoint.ckpt";
  const std::filesystem::path progress = run / "progress.csv";

  long steps = 0;
  bool append = false;
  if (options.resume) {
    steps = learner.load(checkpoint);
    append = learn::cut_progress(progress, kProgressHeader, steps).append;
    rng = Rng(seed + static_cast<std::uint64_t>(steps));
  } else {
    nlohmann::json saved{{"env", env_name},
                         {"method", method},
                         {"seed", seed},
                         {"steps_per_env", steps_per_env},
                         {"hyperparameters", hp},
                         {"config", config_text},
                         {"training_sets", sets.size()}};
    write_atomically(run / "run.json", saved.dump(2) + "\n");
  }
  std::ofstream csv(progress, append ? std::ios::app : std::ios::trunc);
  if (!append) csv << kProgressHeader << "\n";
  csv.flush();

  const long total = steps_per_env * n;
  const long random_steps = config.learning_starts * n;
  const long report_every = options.report_every > 0 ? options.report_every : spec.horizon;
  const long checkpoint_every = options.checkpoint_every * n;
  envs.reset(seed + static_cast<std::uint64_t>(steps));
  ContextSac::Streams streams = learner.streams(n);
  for (int i = 0; i < n; ++i) {
    replay.begin(
        i, envs.observations().subspan(static_cast<size_t>(i) * spec.obs_size, spec.obs_size));
  }

  // Report accumulators.
  std::vector<double> returns(n, 0.0);
  double report_return = 0, report_success = 0;
  int report_episodes = 0;
  std::map<std::string, std::pair<double, long>> sums;
  const auto add = [&](const std::string& k, double v) {
    if (std::isnan(v)) return;
    sums[k].first += v;
    sums[k].second += 1;
  };
  const auto mean = [&](const std::string& k) {
    const auto it = sums.find(k);
    return it == sums.end() || it->second.second == 0
               ? std::nan("")
               : it->second.first / static_cast<double>(it->second.second);
  };
  SamiTrainResult result{.run = run};
  const Clock::time_point start = Clock::now();
  Clock::time_point report_start = start;
  const ProgressBar bar(total, steps, options.progress_bar);
  long report_steps_from = steps, report_updates = 0;
  double update_seconds = 0, report_update_seconds = 0;
  long updates = 0, vector_step = 0, last_checkpoint = steps;
  std::vector<double> actions(static_cast<size_t>(n) * spec.action_size);
  torch::Tensor obs = torch::empty({n, spec.obs_size});

  while (steps < total) {
    // Act: uniform random actions until learning_starts, then the policy with its contexts.
    {
      const auto o = envs.observations();
      std::copy(o.begin(), o.end(), obs.data_ptr<float>());
    }
    const torch::Tensor policy = learner.act(obs, streams, /*deterministic=*/false).first;
    if (steps < random_steps) {
      for (double& a : actions) a = rng.uniform(-1.0, 1.0);
      torch::NoGradGuard no_grad;
      const torch::Tensor random =
          torch::from_blob(actions.data(), {n, spec.action_size}, torch::kFloat64)
              .to(torch::kFloat32);
      streams.prev_actions.copy_(random);
    } else {
      const float* p = policy.data_ptr<float>();
      for (size_t k = 0; k < actions.size(); ++k) actions[k] = p[k];
    }
    const float* taken = streams.prev_actions.data_ptr<float>();
    const double scale = 0.5 * (spec.action_high - spec.action_low);
    std::vector<double> env_actions(actions.size());
    for (size_t k = 0; k < actions.size(); ++k) {
      env_actions[k] = spec.action_low + (actions[k] + 1.0) * scale;
    }
    envs.step(env_actions);
    ++vector_step;
    steps += n;

    // Store the steps; finished trajectories close and new ones open.
    for (int i = 0; i < n; ++i) {
      const bool done = envs.terminated()[i] || envs.truncated()[i];
      const auto row = [&](std::span<const float> x) {
        return x.subspan(static_cast<size_t>(i) * spec.obs_size, spec.obs_size);
      };
      const std::span<const float> next =
          done ? envs.final_observation(i) : row(envs.observations());
      replay.add(i,
                 std::span<const float>(taken + static_cast<size_t>(i) * spec.action_size,
                                        spec.action_size),
                 envs.rewards()[i], next);
      returns[i] += envs.rewards()[i];
      if (!done) continue;
      replay.finish(i, envs.terminated()[i]);
      report_return += returns[i];
      report_success += envs.final_info(i).is_success ? 1 : 0;
      ++report_episodes;
      returns[i] = 0;
      streams.reset(i);
      replay.begin(i, row(envs.observations()));
    }

    // Train every train_freq vector steps once every env has a whole trajectory.
    bool ready = steps >= random_steps;
    for (int i = 0; i < n && ready; ++i) ready = replay.stored(i) > 0;
    if (ready && vector_step % config.train_freq == 0) {
      const Clock::time_point t0 = Clock::now();
      for (int g = 0; g < config.gradient_steps; ++g) {
        const ContextSac::Losses l = learner.update(replay, rng);
        add("critic_loss", l.critic);
        add("actor_loss", l.actor);
        add("alpha", l.alpha);
        add("entropy", l.entropy);
        add("sance_loss", l.sance);
        add("sance_weight", l.weight);
        if (!std::isfinite(l.critic) || !std::isfinite(l.actor)) {
          throw UserError("sami train: the update diverged at step " + std::to_string(steps) +
                          " (critic loss " + csv_cell(l.critic) +
                          "); the last good checkpoint is " + checkpoint.string());
        }
      }
      const double dt = seconds(t0, Clock::now());
      update_seconds += dt;
      report_update_seconds += dt;
      updates += config.gradient_steps;
      report_updates += config.gradient_steps;
    }

    // Progress row, bar and checkpoint.
    const bool stopping = options.stop && options.stop->load() && steps < total;
    const bool last = steps >= total || stopping;
    if (vector_step % report_every == 0 || last) {
      const Clock::time_point now = Clock::now();
      const double sps = (steps - report_steps_from) / std::max(seconds(report_start, now), 1e-9);
      const double gps = report_update_seconds > 0 ? report_updates / report_update_seconds : 0;
      const double ret = report_episodes ? report_return / report_episodes : std::nan("");
      const double success = report_episodes ? report_success / report_episodes : std::nan("");
      csv << steps << "," << report_episodes << "," << csv_cell(ret) << "," << csv_cell(success)
          << "," << csv_cell(mean("critic_loss")) << "," << csv_cell(mean("actor_loss")) << ","
          << csv_cell(mean("alpha")) << "," << csv_cell(mean("entropy")) << ","
          << csv_cell(mean("sance_loss")) << "," << csv_cell(mean("sance_weight")) << ","
          << csv_cell(sps) << "," << csv_cell(gps) << "," << learner.updates() << "\n";
      csv.flush();
      bar.show(steps, seconds(start, now), csv_cell(gps) + " grad/s  return " + csv_cell(ret));
      if (report_episodes) result.last_return = ret;
      report_return = report_success = 0;
      report_episodes = 0;
      sums.clear();
      report_start = now;
      report_steps_from = steps;
      report_updates = 0;
      report_update_seconds = 0;
    }
    if (steps - last_checkpoint >= checkpoint_every || last) {
      learner.save(checkpoint, steps);
      last_checkpoint = steps;
    }
    if (stopping) {
      result.stopped = true;
      break;
    }
  }
  bar.finish();
  result.steps = steps;
  result.updates = learner.updates();
  result.sps = steps / std::max(seconds(start, Clock::now()), 1e-9);
  result.gradient_steps_per_s = update_seconds > 0 ? updates / update_seconds : 0;
  return result;
}

SamiEvalResult sami_evaluate(const SamiEvalOptions& options) {
  const SamiRunFile saved = read_sami_run(options.run);
  const sami::EnvId id = sami::env_from_name(saved.env);
  const std::string method = saved.method;
  const sami::Split split = sami::split_from_name(options.split);
  if (options.episodes < 1) throw UserError("sami evaluate: --episodes must be positive");
  std::string text;
  const SamiConfig config = make_config(id, saved.hyperparameters, text);
  const sami::Spec spec = sami::env_spec(id);
  ContextSac learner(method, spec.obs_size, spec.action_size, config, 0);
  learner.load(options.run / "checkpoint.ckpt");
  const bool panda = id == sami::EnvId::kPandaPush;
  torch::set_num_threads(1);

  SamiEvalResult result{.split = options.split, .skills = panda};
  const std::string stem = "eval_" + options.split;
  result.json = options.run / (stem + ".json");
  result.csv = options.run / (stem + ".csv");
  result.contexts = options.run / ("contexts_" + options.split + ".csv");
  std::ofstream contexts(result.contexts);
  contexts << "task_set,cell,episode,step,mass,damping,crippled,skill,episode_skill";
  for (int k = 0; k < config.context_size; ++k) contexts << ",c" << k;
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
    auto env = sami::make_env(id, {sets[s]}, options.seed + s);
    std::unique_ptr<sami::Renderer> renderer;
    if (options.video) {
      renderer = std::make_unique<sami::Renderer>(*env, 320, 240);
      frame.resize(320 * 240 * 3);
      if (!video) {
        video = std::make_unique<eval::VideoWriter>(options.run / (stem + ".mp4"), 320, 240,
                                                    1.0 / spec.dt);
      }
    }
    SamiCell cell{.name = cell_name(sets[s], panda)};
    std::vector<double> episode_returns;
    for (int e = 0; e < options.episodes; ++e) {
      env->reset();
      // The parameters this episode drew (the task, within its task set): mass, damping, the
      // crippled joints ("0+4"; "none").
      const sami::Info& drawn = env->info();
      const std::string episode_task =
          csv_cell(drawn.mass) + "," + csv_cell(drawn.damping) + "," +
          (drawn.crippled.empty() ? "none" : sami::joints_text(drawn.crippled, "+"));
      ContextSac::Streams streams = learner.streams(1);
      double ret = 0;
      sami::StepResult r;
      std::vector<double> action(spec.action_size);
      do {
        const torch::Tensor o = torch::tensor(to_vector(env->observation())).unsqueeze(0);
        auto [a, c] = learner.act(o, streams, /*deterministic=*/true);
        const float* p = a.data_ptr<float>();
        for (int k = 0; k < spec.action_size; ++k) {
          action[k] = spec.action_low + (p[k] + 1.0) * 0.5 * (spec.action_high - spec.action_low);
        }
        const int step = env->info().steps;
        r = env->step(action);
        ret += r.reward;
        if (step % context_every == 0) {
          episode_rows.push_back(std::to_string(s) + ",\"" + cell.name + "\"," + std::to_string(e) +
                                 "," + std::to_string(step) + "," + episode_task + "," +
                                 std::string(sami::skill_name(env->info().skill)));
          const float* cp = c.data_ptr<float>();
          context_values.insert(context_values.end(), cp, cp + config.context_size);
        }
        if (renderer && e == 0) {
          renderer->render(*env, frame);
          video->write(frame);
        }
      } while (!r.terminated && !r.truncated);
      // The episode's label, known at its end, completes its context rows.
      const std::string episode_skill(sami::skill_name(env->info().episode_skill));
      for (std::string& row : episode_rows) context_rows.push_back(row + "," + episode_skill);
      episode_rows.clear();
      cell.success_rate += env->info().is_success;
      const sami::Skill skill = env->info().episode_skill;
      cell.push += skill == sami::Skill::kPush;
      cell.roll += skill == sami::Skill::kRoll;
      cell.pick_and_place += skill == sami::Skill::kPickAndPlace;
      episode_returns.push_back(ret);
    }
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
        torch::from_blob(context_values.data(), {rows, config.context_size}).to(torch::kFloat64);
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
    for (int k = 0; k < config.context_size; ++k) {
      contexts << "," << csv_cell(context_values[r * config.context_size + k]);
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

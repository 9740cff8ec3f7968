#include "train/evaluation.h"

#include <mujoco/mujoco.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <set>

#include "core/error.h"
#include "core/jsonl.h"
#include "core/npz.h"
#include "core/rng.h"
#include "eval/figures.h"
#include "eval/log_check.h"
#include "eval/video.h"
#include "train/episodes.h"
#include "train/frames.h"

namespace cradle::train {
namespace {

namespace fs = std::filesystem;

// Per-step record of one episode, for its trajectory file and plots.
struct Trajectory {
  std::vector<double> qpos;        // steps x nq
  std::vector<float> actions;      // steps x action dim
  std::vector<std::string> infos;  // steps JSON texts
  std::vector<double> trace;       // steps x the task's trace width
};

// Score over training episodes from the log (per-episode score, plus the cumulative union of
// the task's geom lists when it has some).
void plot_training_log(const envs::EvaluationPanels& panels,
                       const std::vector<nlohmann::json>& entries, const fs::path& file,
                       eval::Figures& figures) {
  eval::Series per_episode{.label = "episode score", .points = true};
  const auto& lists = panels.geom_lists;
  eval::Series cumulative{.label = lists ? lists->union_label : ""};
  std::vector<std::set<int>> seen(lists ? lists->keys.size() : 0);
  for (size_t i = 0; i < entries.size(); ++i) {
    const nlohmann::json& e = entries[i];
    if (!e.contains("score")) continue;
    per_episode.x.push_back(static_cast<double>(i));
    per_episode.y.push_back(e["score"].get<double>());
    if (lists) {
      size_t count = 0;
      for (size_t k = 0; k < seen.size(); ++k) {
        for (int g : e.value(lists->keys[k], std::vector<int>{})) seen[k].insert(g);
        count += seen[k].size();
      }
      cumulative.x.push_back(static_cast<double>(i));
      cumulative.y.push_back(static_cast<double>(count) / lists->union_denominator);
    }
  }
  eval::LinePlot plot{.title = "Training log: score per episode",
                      .x_label = "episode",
                      .y_label = "score",
                      .series = {per_episode}};
  if (!cumulative.y.empty()) plot.series.push_back(cumulative);
  figures.add(plot, file);
}

// Coverage per body part: the fraction of each MIMo body's geoms in each of the task's geom lists
// (self-touch: touched by each hand) over the evaluation episodes.
void plot_coverage(const mjModel* m, const envs::EvaluationPanels::GeomLists& lists,
                   const std::vector<std::vector<std::set<int>>>& episode_lists,
                   const fs::path& file, eval::Figures& figures) {
  eval::BarChart chart{.title = lists.title,
                       .y_label = "fraction of geoms touched",
                       .group_labels = lists.labels,
                       .values = std::vector<std::vector<double>>(lists.keys.size()),
                       .y_range = std::make_pair(0.0, 1.0)};
  std::vector<std::set<int>> touched(lists.keys.size());
  for (const auto& episode : episode_lists) {
    for (size_t k = 0; k < touched.size(); ++k)
      touched[k].insert(episode[k].begin(), episode[k].end());
  }
  for (int body = 0; body < m->nbody; ++body) {
    const int first = m->body_geomadr[body], count = m->body_geomnum[body];
    const char* name = mj_id2name(m, mjOBJ_BODY, body);
    if (count == 0 || !name) continue;
    // Only MIMo's bodies: those whose geoms can appear in the touch lists (below "hip").
    bool mimo = false;
    for (int b = body; b > 0; b = m->body_parentid[b]) {
      const char* n = mj_id2name(m, mjOBJ_BODY, b);
      if (n && std::string(n) == "hip") mimo = true;
    }
    if (!mimo) continue;
    chart.categories.emplace_back(name);
    for (size_t k = 0; k < touched.size(); ++k) {
      int hit = 0;
      for (int g = first; g < first + count; ++g) hit += static_cast<int>(touched[k].count(g));
      chart.values[k].push_back(static_cast<double>(hit) / count);
    }
  }
  figures.add(chart, file, 1200, 600);
}

// The task's per-step trace over one episode, one line per value, with its threshold.
void plot_trace(const envs::EvaluationPanels::Trace& trace, const std::vector<double>& values,
                const fs::path& file, eval::Figures& figures) {
  eval::LinePlot plot{
      .title = trace.title, .x_label = "step", .y_label = trace.y_label, .y_range = trace.y_range};
  if (trace.threshold) plot.h_lines.push_back(*trace.threshold);
  const size_t width = trace.labels.size();
  for (size_t k = 0; k < width; ++k) {
    eval::Series s{.label = trace.labels[k]};
    for (size_t t = 0; width * t + k < values.size(); ++t) s.y.push_back(values[width * t + k]);
    plot.series.push_back(std::move(s));
  }
  figures.add(plot, file);
}

void write_trajectory(const Trajectory& traj, int steps, int nq, int nu,
                      const envs::EvaluationPanels& panels, const fs::path& file) {
  NpzWriter npz(file);
  const auto n = static_cast<std::size_t>(steps);
  npz.add("qpos", traj.qpos, {n, static_cast<std::size_t>(nq)});
  npz.add("action", traj.actions, {n, static_cast<std::size_t>(nu)});
  npz.add_strings("info", traj.infos);
  if (panels.trace && !traj.trace.empty()) {
    npz.add(panels.trace->key, traj.trace, {n, panels.trace->labels.size()});
  }
  npz.close();
}

}  // namespace

Policy random_policy(std::uint64_t seed) {
  auto rng = std::make_shared<Rng>(seed);
  return [rng](const envs::BabyBenchEnv& env, std::span<double> action) {
    env.action_space().sample(*rng, action);
  };
}

EvaluationReport evaluate(const Config& config, const EvaluationOptions& options,
                          const Policy& given_policy) {
  if (options.episodes < 1) throw UserError("--episodes must be at least 1");
  if (options.duration < 1) throw UserError("--duration must be at least 1");
  const fs::path dir = config.save_dir;
  EvaluationReport report;

  // The training scene when there is one (no re-build; under scene/ in current results folders,
  // at the top level in older ones), else the config's.
  fs::path scene_file = dir / scene::kSceneDirName / scene::kSceneFileName;
  if (!fs::exists(scene_file)) scene_file = dir / scene::kSceneFileName;
  auto assets =
      fs::exists(scene_file) ? envs::make_assets(config, scene_file) : envs::make_assets(config);
  envs::BabyBenchEnv env(assets, options.seed);
  const mjModel* m = env.model();
  // Training log score, as the reference prints first (entries checked against this model).
  const fs::path log_file = dir / "logs" / "training.jsonl";
  std::vector<nlohmann::json> log;
  if (fs::exists(log_file)) {
    log = eval::read_training_log(log_file, config.behavior, m->ngeom);
    report.training_episodes = static_cast<int>(log.size());
    report.training_score = eval::training_score(config.behavior, log);
    if (config.behavior == Behavior::kHandRegard)
      report.training_hand_regard = eval::hand_regard_score(log);
  }
  const Policy policy = given_policy ? given_policy : random_policy(options.seed ^ 0x5eedULL);
  // What the task shows: its video panels, per-step trace and geom-list charts.
  const envs::EvaluationPanels panels = env.task().evaluation_panels();
  std::vector<double> trace_step(panels.trace ? panels.trace->labels.size() : 0);
  std::vector<std::vector<std::set<int>>> episode_lists;  // per episode, per geom-list key

  std::error_code ec;
  for (const char* sub : {"trajectories", "plots"}) fs::create_directories(dir / sub, ec);
  // videos/ only holds films: made when filming, and an empty one an earlier evaluation left
  // (remove() takes only an empty folder) goes, so no evaluation leaves an empty videos/.
  if (options.render) {
    fs::create_directories(dir / "videos", ec);
  } else {
    fs::remove(dir / "videos", ec);
  }
  std::unique_ptr<FrameComposer> composer;
  std::vector<std::uint8_t> frame;
  if (options.render) {
    composer = std::make_unique<FrameComposer>(env);
    frame.resize(FrameComposer::kHeight * FrameComposer::kWidth * 3);
  }
  const double step_seconds = m->opt.timestep * config.frame_skip;
  const double fps = options.video_fps > 0 ? options.video_fps : 1.0 / step_seconds;

  std::vector<double> action(env.action_space().size());
  std::vector<double> first_trace;
  // Each episode through the one rollout, exactly `duration` steps (BabyBench runs on past the
  // env's own episode length): after every step its trajectory row and its video frame.
  Trajectory traj;
  std::optional<eval::VideoWriter> video;
  const EpisodePolicy episode_policy{
      .act = [&](const envs::ObservationBuffers&, std::span<double> a) {
        policy(env, a);
        action.assign(a.begin(), a.end());  // the trajectory's row of this step
      }};
  const EpisodeStepFn on_step = [&](int, const envs::Env&, const envs::StepResult&) {
    traj.qpos.insert(traj.qpos.end(), env.data()->qpos, env.data()->qpos + m->nq);
    traj.actions.insert(traj.actions.end(), action.begin(), action.end());
    traj.infos.push_back(env.info().to_json().dump());
    if (panels.trace) {
      env.task().trace(env.data(), trace_step);
      traj.trace.insert(traj.trace.end(), trace_step.begin(), trace_step.end());
    }
    if (video) {
      composer->compose(env, frame);
      video->write(frame);
    }
  };
  for (int i = 0; i < options.episodes; ++i) {
    const auto start = std::chrono::steady_clock::now();
    traj = {};
    traj.qpos.reserve(static_cast<size_t>(options.duration) * m->nq);
    if (options.render) {
      video.emplace(dir / "videos" / ("episode_" + std::to_string(i) + options.video_extension),
                    FrameComposer::kWidth, FrameComposer::kHeight, fps);
    }
    const std::uint64_t seed = options.seed + static_cast<std::uint64_t>(i);
    run_episodes(env, episode_policy, std::span(&seed, 1), options.duration, on_step, nullptr,
                 /*fixed_length=*/true);
    if (video) video->close();
    video.reset();
    write_trajectory(traj, options.duration, m->nq, static_cast<int>(action.size()), panels,
                     dir / "trajectories" / ("episode_" + std::to_string(i) + ".npz"));
    if (i == 0) first_trace = traj.trace;

    EpisodeResult result;
    result.steps = options.duration;
    result.score = env.score();
    const envs::Info& info = env.info();
    if (const int k = info.find("right_hand_touches"); k >= 0) {
      result.right_hand_touches.assign(info.list(k).begin(), info.list(k).end());
    }
    if (const int k = info.find("left_hand_touches"); k >= 0) {
      result.left_hand_touches.assign(info.list(k).begin(), info.list(k).end());
    }
    if (panels.geom_lists) {
      auto& lists = episode_lists.emplace_back();
      for (const std::string& key : panels.geom_lists->keys) {
        const int k = info.find(key);
        lists.emplace_back();
        if (k >= 0) lists.back().insert(info.list(k).begin(), info.list(k).end());
      }
    }
    if (config.behavior == Behavior::kHandRegard) {
      nlohmann::json entry = info.to_json();
      entry["steps"] = options.duration;
      result.hand_regard = eval::hand_regard_episode_score(entry);
    }
    result.wall_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (!options.quiet) {
      std::printf("episode %d: score %.4f (%.1f s)\n", i, result.score, result.wall_seconds);
    }
    report.episodes.push_back(std::move(result));
  }

  // Mean and standard deviation of the episode scores.
  double sum = 0, sq = 0;
  for (const EpisodeResult& e : report.episodes) sum += e.score;
  report.mean = sum / options.episodes;
  for (const EpisodeResult& e : report.episodes)
    sq += (e.score - report.mean) * (e.score - report.mean);
  report.std = std::sqrt(sq / options.episodes);

  // Plots (matplotlib, from plots/figures.json).
  eval::Figures figures;
  const fs::path plots = dir / "plots";
  if (!log.empty()) plot_training_log(panels, log, plots / "training_score.png", figures);
  if (panels.geom_lists) {
    plot_coverage(m, *panels.geom_lists, episode_lists, plots / panels.geom_lists->file, figures);
  }
  if (panels.trace) {
    plot_trace(*panels.trace, first_trace, plots / panels.trace->file, figures);
  }
  if (!figures.empty()) figures.draw(plots / "figures.json");

  // evaluation.json: every score, the config, the seed and versions.
  nlohmann::json out = report.to_json();
  out["config"] = to_json(config);
  out["seed"] = options.seed;
  out["episodes_requested"] = options.episodes;
  out["duration"] = options.duration;
  out["policy_actions"] = given_policy ? options.policy_actions : "random";
  out["versions"] = {{"cradle", CRADLE_VERSION}, {"mujoco", mj_versionString()}};
  std::ofstream file(dir / "evaluation.json");
  file << out.dump(2) << "\n";
  if (!file) throw UserError("cannot write '" + (dir / "evaluation.json").string() + "'");
  return report;
}

nlohmann::json EvaluationReport::to_json() const {
  nlohmann::json j;
  j["training_log"] = {{"episodes", training_episodes}};
  if (training_score) j["training_log"]["score"] = *training_score;
  if (training_hand_regard) {
    j["training_log"]["hand_regard_reference"] = training_hand_regard->reference;
    j["training_log"]["hand_regard_either"] = training_hand_regard->either;
  }
  nlohmann::json list = nlohmann::json::array();
  for (const EpisodeResult& e : episodes) {
    nlohmann::json x = {{"steps", e.steps}, {"wall_seconds", e.wall_seconds}};
    if (!std::isnan(e.score)) x["score"] = e.score;
    if (e.hand_regard) {
      x["hand_regard_reference"] = e.hand_regard->reference;
      x["hand_regard_either"] = e.hand_regard->either;
    }
    if (!e.right_hand_touches.empty() || !e.left_hand_touches.empty()) {
      x["right_hand_touches"] = e.right_hand_touches;
      x["left_hand_touches"] = e.left_hand_touches;
    }
    list.push_back(std::move(x));
  }
  j["episodes"] = std::move(list);
  if (!std::isnan(mean)) j["score"] = {{"mean", mean}, {"std", std}};
  return j;
}

}  // namespace cradle::train

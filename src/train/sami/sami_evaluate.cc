// `cradle sami evaluate`: a trained SaMI run's policy on every task set (cell) of a split, through
// the one evaluation rollout; per cell the success rate, the returns and (Panda) the skill mix,
// and the contexts the policy acted with, with their 2-D PCA.
#include <torch/torch.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/error.h"
#include "core/sealed_file.h"
#include "envs/sami/sami_env.h"
#include "eval/video.h"
#include "learn/meta/sami_learner.h"
#include "sami/env.h"
#include "sami/render.h"
#include "sami/task.h"
#include "train/episodes.h"
#include "train/loop.h"
#include "train/run_policy.h"
#include "train/sami/sami_experiment.h"

namespace cradle::train {
namespace {

namespace fs = std::filesystem;

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

SamiEvalResult sami_evaluate(const SamiEvalOptions& options) {
  const SamiRunFile saved = read_sami_run(options.run);
  const sami::EnvId id = sami::env_from_name(saved.env);
  const std::string method = saved.method;
  const sami::Split split = sami::split_from_name(options.split);
  if (options.episodes < 1) throw UserError("sami evaluate: --episodes must be positive");
  const sami::Spec spec = sami::env_spec(id);
  const bool panda = id == sami::EnvId::kPandaPush;
  // The run's latest checkpoint, acting deterministically (its learner's contexts recorded).
  const RunPolicy policy = load_run_policy(options.run, "latest");
  torch::set_num_threads(1);

  SamiEvalResult result{.split = options.split, .skills = panda};
  const std::string stem = "eval_" + options.split;
  result.json = options.run / (stem + ".json");
  result.csv = options.run / (stem + ".csv");
  result.contexts = options.run / ("contexts_" + options.split + ".csv");
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
    std::string episode_task;
    const std::vector<EpisodeOutcome> episodes = run_episodes(
        adapter, policy.episode_policy(), options.episodes, 0,
        [&](int e, const envs::Env&, const envs::StepResult& r) {
          const sami::Info& info = env.info();
          const int step = info.steps - 1;
          // The parameters this episode drew (the task, within its task set): mass, damping, the
          // crippled joints ("0+4"; "none").
          if (step == 0) {
            episode_task = csv_cell(info.mass) + "," + csv_cell(info.damping) + "," +
                           (info.crippled.empty() ? "none" : sami::joints_text(info.crippled, "+"));
          }
          if (step % context_every == 0) {
            const std::span<const float> c = learn::meta::last_context(policy.learner());
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
    // The cell's shares and return statistics over its episodes, and the split's totals.
    cell.episodes = options.episodes;
    const double k = options.episodes;
    all_success += cell.success_rate;
    all_episodes += options.episodes;
    for (double* share : {&cell.success_rate, &cell.push, &cell.roll, &cell.pick_and_place})
      *share /= k;
    for (const EpisodeOutcome& o : episodes) cell.mean_return += o.episode_return;
    cell.mean_return /= k;
    all_return += cell.mean_return * k;
    for (const EpisodeOutcome& o : episodes)
      cell.std_return +=
          (o.episode_return - cell.mean_return) * (o.episode_return - cell.mean_return);
    cell.std_return = std::sqrt(cell.std_return / k);
    result.cells.push_back(cell);
  }
  if (video) video->close();
  result.success_rate = all_success / all_episodes;
  result.mean_return = all_return / all_episodes;

  // Context pictures: the 2-D PCA of every recorded context (centred, top two right singular
  // vectors).
  const long rows = static_cast<long>(context_rows.size());
  const long context_size = rows > 0 ? static_cast<long>(context_values.size()) / rows : 0;
  std::ostringstream contexts;
  contexts << "task_set,cell,episode,step,mass,damping,crippled,skill,episode_skill";
  for (long k = 0; k < context_size; ++k) contexts << ",c" << k;
  contexts << ",pc1,pc2\n";
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
    for (long k = 0; k < context_size; ++k) {
      contexts << "," << csv_cell(context_values[r * context_size + k]);
    }
    contexts << "," << csv_cell(pc[r][0].item<double>()) << "," << csv_cell(pc[r][1].item<double>())
             << "\n";
  }
  write_atomically(result.contexts, contexts.str());

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

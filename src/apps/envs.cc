// `cradle envs [--family F] [--json] [ID]`: the env registry. Without an id, every listed env (id,
// family, episode length, the task parameters a teacher can set); with one, that env built once:
// its observation and action spaces as well.
#include <cmath>
#include <cstdio>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "apps/commands.h"
#include "core/error.h"
#include "core/spaces.h"
#include "envs/registry.h"

namespace cradle::apps {
namespace {

nlohmann::ordered_json box_json(const Box& box) {
  nlohmann::ordered_json j;
  j["shape"] = box.shape;
  j["dtype"] = std::string(dtype_name(box.dtype));
  // Bounds shown when the same for every entry (JSON has no infinity: null).
  auto bound = [](double v) { return std::isfinite(v) ? nlohmann::ordered_json(v) : nullptr; };
  if (!box.low.empty()) {
    j["low"] = bound(box.low.front());
    j["high"] = bound(box.high.front());
  }
  return j;
}

nlohmann::ordered_json spec_json(const envs::EnvSpec& s) {
  nlohmann::ordered_json j;
  j["id"] = s.id;
  j["family"] = s.family;
  j["summary"] = s.summary;
  j["max_episode_steps"] = s.max_episode_steps;
  j["aliases"] = s.aliases;
  j["task_parameters"] = nlohmann::ordered_json::array();
  for (const envs::TaskParameter& p : s.parameters)
    j["task_parameters"].push_back({{"name", p.name}, {"low", p.low}, {"high", p.high}});
  if (s.natural_envs > 1) j["training_task_sets"] = s.natural_envs;
  return j;
}

std::string box_text(const Box& box) {
  std::string shape;
  for (int d : box.shape) shape += (shape.empty() ? "" : ", ") + std::to_string(d);
  return std::string(dtype_name(box.dtype)) + "[" + shape + "]";
}

}  // namespace

void register_envs(CLI::App& app) {
  struct Options {
    std::string id, family;
    bool json = false;
  };
  auto opts = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "envs", "List every env id (BabyBench, MIMo, TeachMyAgent, SaMI), or describe one");
  cmd->add_option("id", opts->id, "An env id to describe (builds it once to show its spaces)");
  cmd->add_option("--family", opts->family, "Only this family's ids")
      ->check(CLI::IsMember({"babybench", "mimo", "tma", "sami"}));
  cmd->add_flag("--json", opts->json, "Print JSON");
  cmd->callback([opts] {
    if (!opts->id.empty()) {
      const envs::EnvSpec spec = envs::env_spec(opts->id);
      const std::unique_ptr<envs::Env> env = envs::make_env(spec.id, 0);
      nlohmann::ordered_json j = spec_json(spec);
      for (const auto& [key, box] : env->observation_space().entries)
        j["observation_space"][key] = box_json(box);
      j["action_space"] = box_json(env->action_space());
      if (opts->json) {
        std::printf("%s\n", j.dump(2).c_str());
        return;
      }
      std::printf("%s  (%s)\n  %s\n  episode: %d steps\n", spec.id.c_str(), spec.family.c_str(),
                  spec.summary.c_str(), spec.max_episode_steps);
      for (const auto& [key, box] : env->observation_space().entries)
        std::printf("  observation %s: %s\n", key.c_str(), box_text(box).c_str());
      std::printf("  action: %s in [%g, %g]\n", box_text(env->action_space()).c_str(),
                  env->action_space().low.front(), env->action_space().high.front());
      for (const envs::TaskParameter& p : spec.parameters)
        std::printf("  task parameter %s in [%g, %g]\n", p.name.c_str(), p.low, p.high);
      for (const std::string& a : spec.aliases) std::printf("  alias %s\n", a.c_str());
      return;
    }
    nlohmann::ordered_json all = nlohmann::ordered_json::array();
    if (!opts->json)
      std::printf("%-40s %-9s %6s  %s\n", "id", "family", "steps", "task parameters");
    for (const envs::EnvSpec& s : envs::env_specs()) {
      if (!opts->family.empty() && s.family != opts->family) continue;
      if (opts->json) {
        all.push_back(spec_json(s));
        continue;
      }
      std::string params;
      for (const envs::TaskParameter& p : s.parameters)
        params += (params.empty() ? "" : ",") + p.name;
      std::printf("%-40s %-9s %6d  %s\n", s.id.c_str(), s.family.c_str(), s.max_episode_steps,
                  params.empty() ? "-" : params.c_str());
    }
    if (opts->json) std::printf("%s\n", all.dump(2).c_str());
  });
}

}  // namespace cradle::apps

#include "train/families.h"

#include <nlohmann/json.hpp>
#include <utility>

#include "core/error.h"
#include "train/sami/sami_experiment.h"
#include "train/tma_student.h"

namespace cradle::train {
namespace {

// Every declared task parameter in its declared range.
CurriculumSpec declared_space(const envs::EnvSpec& env) {
  nlohmann::ordered_json bounds = nlohmann::ordered_json::object();
  for (const envs::TaskParameter& p : env.parameters) bounds[p.name] = {p.low, p.high};
  CurriculumSpec spec;
  spec.space = teach::TaskSpace::from_json(bounds);
  return spec;
}

// BabyBench's envs reward nothing: the teacher hears the behaviour score.
CurriculumSpec babybench_curriculum(const envs::EnvSpec& env) {
  CurriculumSpec spec = declared_space(env);
  spec.env_options.use_score = true;
  return spec;
}

// TeachMyAgent's benchmark facts, as `cradle tma run` sets them (train/tma_student.h): Stump
// Tracks' 2-D space with its easy corner, returns in [-150, 350] (Parkour 360), high expert
// knowledge.
CurriculumSpec tma_curriculum(const envs::EnvSpec& env) {
  const envs::EnvIdParts id = envs::split_env_id(env.id);
  const StudentEnv student =
      tma_student_env({.env = tma::parse_env_id(id.name), .body = id.variant});
  CurriculumSpec spec;
  spec.space = student.space;
  spec.reward_lb = student.reward_lb;
  spec.reward_ub = student.reward_ub;
  spec.initial_dist = student.initial_dist;
  spec.expert_knowledge = "high";
  return spec;
}

// The registry: one line per family.
const std::pair<std::string_view, Family> kFamilies[] = {
    {"babybench", {.curriculum = babybench_curriculum}},
    {"mimo", {.curriculum = declared_space}},
    {"tma", {.curriculum = tma_curriculum}},
    {"sami",
     {.presets = sami_presets,
      .curriculum = declared_space,
      .outputs = {"eval_*.json", "eval_*.csv", "eval_*.mp4", "contexts_*.csv", "checkpoint.ckpt",
                  "progress*.csv"}}},
};

}  // namespace

const Family& family(std::string_view name) {
  std::string names;
  for (const auto& [known, entry] : kFamilies) {
    if (known == name) return entry;
    names += (names.empty() ? "" : ", ") + std::string(known);
  }
  throw UserError("env family '" + std::string(name) + "' is not one the run knows (" + names +
                  ")");
}

}  // namespace cradle::train

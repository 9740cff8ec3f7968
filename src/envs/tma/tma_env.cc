#include "envs/tma/tma_env.h"

#include <algorithm>
#include <cctype>
#include <map>
#include <string>
#include <vector>

#include "core/error.h"
#include "envs/action_check.h"

namespace cradle::envs {
namespace {

DictSpace observation_space_of(const tma::TmaEnv& env) {
  // float32, as the reference's observation space: the env computes in float64 (its reward reads
  // the head angle unrounded) and the observation is that rounded once.
  return DictSpace{{{"observation", Box::unbounded({env.observation_size()}, DType::kFloat32)}}};
}

}  // namespace

TmaEnvAdapter::TmaEnvAdapter(const tma::TmaOptions& options, std::shared_ptr<const tma::Cppn> cppn)
    : env_(options, std::move(cppn)),
      observation_space_(observation_space_of(env_)),
      action_space_(Box::uniform({env_.action_size()}, DType::kFloat64, -1.0, 1.0)),
      buffers_(observation_space_) {
  success_slot_ = info_.declare("is_success", InfoType::kBool);
  failure_slot_ = info_.declare("is_failure", InfoType::kBool);
  copy_observation();
}

void TmaEnvAdapter::set_reset_options(const ResetOptions& options) {
  // Group name_<i> options into the vector parameters; the env checks names and ranges.
  std::map<std::string, std::map<int, double>> vectors;
  std::vector<tma::TaskParam> params;
  for (const auto& [name, value] : options) {
    const std::size_t cut = name.rfind('_');
    const bool indexed = cut != std::string::npos && cut + 1 < name.size() &&
                         std::all_of(name.begin() + cut + 1, name.end(),
                                     [](unsigned char c) { return std::isdigit(c); });
    const std::string base = indexed ? name.substr(0, cut) : name;
    if (indexed && (base == "input_vector" || base == "stump_width" || base == "stump_rot")) {
      vectors[base][std::stoi(name.substr(cut + 1))] = value;
    } else {
      params.push_back({name, {value}});
    }
  }
  for (const auto& [base, values] : vectors) {
    tma::TaskParam p{base, {}};
    for (const auto& [index, value] : values) {
      if (index != static_cast<int>(p.second.size())) {
        throw UserError("reset option " + base + "_" + std::to_string(p.second.size()) +
                        " is missing (expected " + base + "_0, " + base + "_1, ...)");
      }
      p.second.push_back(value);
    }
    params.push_back(std::move(p));
  }
  env_.set_environment(params);
}

void TmaEnvAdapter::reset(std::optional<std::uint64_t> seed) {
  env_.reset(seed);
  info_.clear();
  copy_observation();
}

StepResult TmaEnvAdapter::step(std::span<const double> action) {
  check_finite_actions(action);
  const tma::TmaStep r = env_.step(action);
  info_.steps = env_.episode_steps() - 1;
  info_.set(success_slot_, r.success);
  info_.set(failure_slot_, r.terminated && r.reward == -100);
  copy_observation();
  return StepResult{.reward = r.reward, .terminated = r.terminated, .truncated = r.truncated};
}

void TmaEnvAdapter::copy_observation() {
  const std::span<const double> obs = env_.observation();
  std::ranges::transform(obs, buffers_.f32(0).begin(),
                         [](double v) { return static_cast<float>(v); });
}

std::vector<TaskParameter> tma_task_parameters(tma::EnvId env, int input_cppn_dim) {
  if (env == tma::EnvId::kStumpTracks) return {{"stump_height", 0, 3}, {"obstacle_spacing", 0, 6}};
  std::vector<TaskParameter> out;
  const double standard[3][2] = {{-0.35, 0.05}, {0.6, 1.0}, {-0.1, 0.3}};
  for (int k = 0; k < input_cppn_dim; ++k) {
    const bool three = input_cppn_dim == 3;
    out.push_back({"input_vector_" + std::to_string(k), three ? standard[k][0] : -1.0,
                   three ? standard[k][1] : 1.0});
  }
  out.insert(out.end(), {{"water_level", 0, 1},
                         {"creepers_width", 0.25, 0.25},
                         {"creepers_height", 0, 4},
                         {"creepers_spacing", 0, 5},
                         {"terrain_cppn_scale", 10, 10}});
  return out;
}

}  // namespace cradle::envs

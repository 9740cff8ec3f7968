#include "envs/registry.h"

#include <algorithm>
#include <filesystem>
#include <optional>
#include <utility>

#include "core/config.h"
#include "core/error.h"
#include "core/resources.h"
#include "envs/babybench.h"
#include "envs/mimo/sample_env.h"
#include "envs/sami/sami_env.h"
#include "envs/tma/tma_env.h"
#include "sami/env.h"
#include "sami/models.h"
#include "sami/task.h"
#include "tma/agent.h"
#include "tma/physics.h"
#include "tma/tma_env.h"

namespace cradle::envs {

EnvIdParts split_env_id(std::string_view id) {
  EnvIdParts p;
  const size_t slash = id.find('/');
  if (slash == std::string_view::npos) return p;
  p.family = id.substr(0, slash);
  const std::string_view rest = id.substr(slash + 1);
  const size_t colon = rest.find(':');
  p.name = rest.substr(0, colon);
  if (colon != std::string_view::npos) p.variant = rest.substr(colon + 1);
  return p;
}

namespace {

namespace fs = std::filesystem;

// The bundled BabyBench configs: id name, file under configs/, the reference's gym id.
struct BundledConfig {
  const char* name;
  const char* file;  // nullptr: the documented defaults
  const char* alias;
};
constexpr BundledConfig kConfigs[] = {
    {"default", nullptr, "BabyBench"},
    {"selftouch", "config_selftouch.yml", "BabyBench-SelfTouch"},
    {"handregard", "config_handregard.yml", "BabyBench-HandRegard"},
    {"test_installation", "config_test_installation.yml", nullptr},
};

// The folder of the bundled configs: an installed copy's own, else the source tree's.
fs::path config_dir() {
  if (const auto& installed = installed_resources()) return *installed / "configs";
  return CRADLE_CONFIG_SOURCE_DIR;
}

bool is_yaml(std::string_view id) { return id.ends_with(".yml") || id.ends_with(".yaml"); }

// "MIMoReach-v0" -> "reach", "MIMoBenchV2-v0" -> "bench-v2".
std::string mimo_short_name(std::string_view registered) {
  std::string s(registered.substr(4, registered.size() - 4 - 3));
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    const char c = s[i];
    if (c == 'V' && i + 1 < s.size() && std::isdigit(static_cast<unsigned char>(s[i + 1]))) {
      out += "-v";
    } else {
      out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    }
  }
  return out;
}

std::vector<TaskParameter> sami_parameters(sami::EnvId id) {
  const sami::Varies v = sami::env_varies(id);
  std::vector<TaskParameter> out;
  if (v.mass)
    out.push_back({"mass", SamiEnvAdapter::kFactorRange[0], SamiEnvAdapter::kFactorRange[1]});
  if (v.damping)
    out.push_back({"damping", SamiEnvAdapter::kFactorRange[0], SamiEnvAdapter::kFactorRange[1]});
  if (v.cells) {
    out.push_back({"table_friction", SamiEnvAdapter::kCellRange[0], SamiEnvAdapter::kCellRange[1]});
    out.push_back({"cube_mass", SamiEnvAdapter::kCellRange[0], SamiEnvAdapter::kCellRange[1]});
  }
  return out;
}

std::vector<EnvSpec> build_specs() {
  std::vector<EnvSpec> specs;
  // BabyBench: MIMo in the BabyBench scenes, one id per bundled config.
  for (const BundledConfig& c : kConfigs) {
    const Config config = c.file ? load_config(config_dir() / c.file) : default_config();
    EnvSpec s{.id = std::string("babybench/") + c.name,
              .family = "babybench",
              .summary = c.file ? std::string("BabyBench with configs/") + c.file
                                : "BabyBench with the documented defaults",
              .max_episode_steps = config.max_episode_steps,
              .parameters = babybench_task_parameters(config)};
    if (c.file) s.config = (config_dir() / c.file).string();
    if (c.alias) s.aliases.push_back(c.alias);
    specs.push_back(std::move(s));
  }
  // MIMo's sample tasks, by the reference's registration.
  for (const SampleDefinition& d : sample_definitions()) {
    specs.push_back({.id = "mimo/" + mimo_short_name(d.name),
                     .family = "mimo",
                     .summary = "MIMo sample task " + d.name,
                     .max_episode_steps = d.max_episode_steps,
                     .parameters = d.parameters,
                     .aliases = {d.name}});
  }
  // TeachMyAgent: Stump Tracks with the walkers and climbers, Parkour with every body.
  for (tma::EnvId env : {tma::EnvId::kStumpTracks, tma::EnvId::kParkour}) {
    for (const std::string& body : tma::embodiment_names()) {
      const tma::BodyKind kind = tma::embodiment(body).kind;
      if (env == tma::EnvId::kStumpTracks && kind != tma::BodyKind::kWalker &&
          kind != tma::BodyKind::kClimber)
        continue;
      const std::string name = env == tma::EnvId::kStumpTracks ? "stump-tracks" : "parkour";
      specs.push_back({.id = "tma/" + name + ":" + body,
                       .family = "tma",
                       .summary = "TeachMyAgent " + name + " with the " +
                                  std::string(tma::kind_name(kind)) + " " + body,
                       .max_episode_steps = tma::kMaxEpisodeSteps,
                       .parameters = tma_task_parameters(env)});
    }
  }
  // SaMI: every env on each named split.
  for (sami::EnvId id : sami::all_envs()) {
    const std::string name(sami::env_name(id));
    for (sami::Split split : {sami::Split::kTrain, sami::Split::kModerate, sami::Split::kExtreme}) {
      const std::string split_name(sami::split_name(split));
      EnvSpec s{.id = "sami/" + name + ":" + split_name,
                .family = "sami",
                .summary = "SaMI " + name + " on its " + split_name + " task sets",
                .max_episode_steps = sami::env_spec(id).horizon,
                .parameters = sami_parameters(id),
                .natural_envs = static_cast<int>(sami_vector_sets(id, split_name).size())};
      if (split == sami::Split::kTrain) s.aliases.push_back("sami/" + name);
      specs.push_back(std::move(s));
    }
  }
  return specs;
}

// Levenshtein distance, case-insensitive.
int distance(std::string_view a, std::string_view b) {
  std::vector<int> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = static_cast<int>(j);
  for (size_t i = 1; i <= a.size(); ++i) {
    int diagonal = row[0];
    row[0] = static_cast<int>(i);
    for (size_t j = 1; j <= b.size(); ++j) {
      const int up = row[j];
      const bool same = std::tolower(static_cast<unsigned char>(a[i - 1])) ==
                        std::tolower(static_cast<unsigned char>(b[j - 1]));
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (same ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

// The listed spec of an id or alias, or null.
const EnvSpec* find_listed(std::string_view id) {
  for (const EnvSpec& s : env_specs()) {
    if (s.id == id || std::ranges::find(s.aliases, id) != s.aliases.end()) return &s;
  }
  return nullptr;
}

[[noreturn]] void unknown(std::string_view id) {
  std::string close;
  for (const std::string& c : close_env_ids(id)) close += (close.empty() ? "" : ", ") + c;
  throw UserError("unknown env id '" + std::string(id) + "' (closest: " + close +
                  "; `cradle envs` lists them all)");
}

// Options a family does not take are refused by name.
void refuse_options(const EnvOptions& options, std::string_view family) {
  if (!options.empty()) {
    throw UserError("env option '" + options.begin()->first + "' is not one " +
                    std::string(family) + " envs take (they take none)");
  }
}

EnvMaker babybench_maker(const Config& config, const EnvOptions& options) {
  refuse_options(options, "BabyBench");
  auto assets = make_assets(config);
  return [assets](int, std::uint64_t seed) -> std::unique_ptr<Env> {
    return std::make_unique<BabyBenchEnv>(assets, seed);
  };
}

EnvMaker mimo_maker(const std::string& registered, const EnvOptions& options) {
  SampleOptions so;
  so.actuation = ActuationModel::kSpringDamper;  // the reference's default
  for (const auto& [name, value] : options) {
    if (name == "actuation") {
      if (value == "spring_damper") {
        so.actuation = ActuationModel::kSpringDamper;
      } else if (value == "muscle") {
        so.actuation = ActuationModel::kMuscle;
      } else {
        throw UserError("env option actuation = '" + value +
                        "' (expected spring_damper or muscle)");
      }
    } else if (name == "jitter" || name == "position_inaccurate" || name == "palm_up") {
      // Catch's variants (`cradle illustrate --jitter` ...).
      if (value != "true" && value != "false")
        throw UserError("env option " + name + " = '" + value + "' (expected true or false)");
      (name == "jitter"    ? so.jitter
       : name == "palm_up" ? so.palm_up
                           : so.position_inaccurate) = value == "true";
    } else {
      throw UserError("env option '" + name +
                      "' is not one MIMo sample envs take (expected actuation, jitter, "
                      "position_inaccurate or palm_up)");
    }
  }
  auto assets = make_sample_assets(registered, so);
  return [assets](int, std::uint64_t seed) -> std::unique_ptr<Env> {
    return make_sample_env(assets, seed);
  };
}

EnvMaker tma_maker(const EnvIdParts& p, const EnvOptions& options) {
  tma::TmaOptions o{.env = tma::parse_env_id(p.name), .body = p.variant};
  if (p.variant.empty()) {
    throw UserError("env id 'tma/" + p.name + "' names no embodiment (expected tma/" + p.name +
                    ":<embodiment>, e.g. tma/" + p.name + ":old_classic_bipedal)");
  }
  tma::embodiment(p.variant);  // UserError naming the known bodies
  for (const auto& [name, value] : options) tma::set_option(o, name, value);
  // The CPPN (Parkour) is built once and shared.
  auto first = std::make_shared<TmaEnvAdapter>(o);
  std::shared_ptr<const tma::Cppn> cppn = first->env().cppn();
  return [o, cppn, first](int, std::uint64_t seed) mutable -> std::unique_ptr<Env> {
    auto env = std::make_unique<TmaEnvAdapter>(o, cppn);
    env->reset(seed);
    return env;
  };
}

EnvMaker sami_maker(const EnvIdParts& p, const EnvOptions& options) {
  const sami::EnvId id = sami::env_from_name(p.name);
  const std::string split = p.variant.empty() ? "train" : p.variant;
  sami::Options so;
  for (const auto& [name, value] : options) {
    if (name != "contact_forces")
      throw UserError("env option '" + name +
                      "' is not one SaMI envs take (expected "
                      "contact_forces)");
    if (value != "0" && value != "1" && value != "true" && value != "false")
      throw UserError("env option contact_forces = '" + value + "' (expected true or false)");
    so.contact_forces = value == "1" || value == "true";
  }
  const std::vector<sami::TaskSet> all = sami::task_sets(id, split);
  sami::validate(id, all);
  const std::vector<sami::TaskSet> each = sami_vector_sets(id, split);
  const sami::ModelPtr model = sami::compile_robot(sami::env_spec(id).robot);
  return [id, all, each, model, so](int index, std::uint64_t seed) -> std::unique_ptr<Env> {
    std::vector<sami::TaskSet> sets =
        index < 0 ? all : std::vector<sami::TaskSet>{each[index % each.size()]};
    auto env =
        std::make_unique<SamiEnvAdapter>(sami::make_env(id, std::move(sets), seed, model, so));
    env->reset(seed);
    return env;
  };
}

}  // namespace

const std::vector<EnvSpec>& env_specs() {
  static const std::vector<EnvSpec> specs = build_specs();
  return specs;
}

std::vector<std::string> close_env_ids(std::string_view id, int count) {
  std::vector<std::pair<int, std::string>> scored;
  for (const EnvSpec& s : env_specs()) {
    int best = distance(id, s.id);
    for (const std::string& a : s.aliases) best = std::min(best, distance(id, a));
    scored.emplace_back(best, s.id);
  }
  std::ranges::stable_sort(scored, {}, &std::pair<int, std::string>::first);
  std::vector<std::string> out;
  for (int i = 0; i < count && i < static_cast<int>(scored.size()); ++i)
    out.push_back(scored[i].second);
  return out;
}

EnvSpec env_spec(std::string_view id) {
  if (const EnvSpec* s = find_listed(id)) return *s;
  if (is_yaml(id)) {
    const Config config = load_config(fs::path(id));
    return {.id = std::string(id),
            .family = "babybench",
            .summary = "BabyBench with " + std::string(id),
            .max_episode_steps = config.max_episode_steps,
            .parameters = babybench_task_parameters(config),
            .config = std::string(id)};
  }
  const EnvIdParts p = split_env_id(id);
  if (p.family == "sami" && !p.name.empty() && is_yaml(p.variant)) {
    const sami::EnvId sid = sami::env_from_name(p.name);
    return {.id = std::string(id),
            .family = "sami",
            .summary = "SaMI " + p.name + " on the task sets of " + p.variant,
            .max_episode_steps = sami::env_spec(sid).horizon,
            .parameters = sami_parameters(sid),
            .natural_envs = static_cast<int>(sami_vector_sets(sid, p.variant).size())};
  }
  // A body listed for no env (a swimmer on Stump Tracks) is still the env's to accept or refuse.
  if (p.family == "tma" && !p.name.empty() && !p.variant.empty()) {
    const tma::EnvId env = tma::parse_env_id(p.name);
    tma::embodiment(p.variant);
    return {.id = std::string(id),
            .family = "tma",
            .summary = "TeachMyAgent " + p.name + " with " + p.variant,
            .max_episode_steps = tma::kMaxEpisodeSteps,
            .parameters = tma_task_parameters(env)};
  }
  unknown(id);
}

EnvMaker env_maker(std::string_view id, const EnvOptions& options) {
  const EnvSpec spec = env_spec(id);
  if (spec.family == "babybench") {
    return babybench_maker(spec.config.empty() ? default_config() : load_config(spec.config),
                           options);
  }
  if (spec.family == "mimo") return mimo_maker(spec.aliases.at(0), options);
  const EnvIdParts p = split_env_id(spec.id);
  if (spec.family == "tma") return tma_maker(p, options);
  return sami_maker(p, options);
}

std::unique_ptr<Env> make_env(std::string_view id, std::uint64_t seed, const EnvOptions& options) {
  return env_maker(id, options)(-1, seed);
}

}  // namespace cradle::envs

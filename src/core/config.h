// Run configuration: the BabyBench YAML keys (same names, types and documented defaults) plus a
// few Cradle extensions. Parsing is strict: a key that is present but wrong is a UserError.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "core/groups.h"

namespace cradle {

enum class Behavior { kNone, kSelfTouch, kHandRegard };
enum class SceneKind { kBase, kCrib, kCubes };
enum class ActuationModel { kSpringDamper, kMuscle, kPositional };
enum class TouchFunction { kNormal, kForceVector, kForceVectorGlobal };
enum class TouchResponse { kNearest, kSpreadLinear };

// Documented touch_* defaults: every group senses touch except the eyes.
constexpr GroupFlags default_touch_groups() {
  GroupFlags flags = GroupFlags::all(true);
  flags[Group::kEyes] = false;
  return flags;
}

// One run's settings. Member defaults are the API page's documented defaults.
struct Config {
  std::string save_dir = "results/test_installation";
  Behavior behavior = Behavior::kNone;
  SceneKind scene = SceneKind::kBase;
  int max_episode_steps = 1000;
  int frame_skip = 1;
  int render_size = 480;
  int save_logs_every = 1000;
  // Parsed and kept for fidelity; the reference env ignores them (always full proprioception).
  bool proprio_velocity = true;
  bool proprio_torque = true;
  bool proprio_limits = true;
  bool proprio_actuation = true;
  bool vestibular_active = true;
  bool vision_active = true;
  int vision_resolution = 64;
  bool touch_active = true;
  double touch_scale = 1.0;
  TouchFunction touch_function = TouchFunction::kNormal;
  TouchResponse touch_response = TouchResponse::kNearest;
  GroupFlags touch_groups = default_touch_groups();
  ActuationModel actuation_model = ActuationModel::kSpringDamper;
  GroupFlags act_groups = GroupFlags::all(true);
  GroupFlags lock_groups = GroupFlags::all(false);
  // Cradle extensions (not in the reference kit).
  double hand_regard_half_angle = 15.0;  // degrees, central field-of-view half-angle
  bool hand_regard_occlusion = false;    // ray-cast occlusion test for hand regard
  // Crib: the mattress's low friction (0.1) applies to MIMo (contact priority). The reference's
  // mattress has no priority, so MIMo meets his own friction (1-5) on it: false by default.
  bool mattress_friction_applies = false;

  // Touch produces observations only when active and the sensor scale is positive.
  bool touch_enabled() const { return touch_active && touch_scale > 0.0; }

  friend bool operator==(const Config&, const Config&) = default;
};

// The documented defaults (same as a value-initialised Config).
Config default_config();

// The reference kit's config_test_installation.yml (configs/ holds the same file), built in so
// `cradle test-installation` needs no file.
Config test_installation_config();

// Parses YAML text; `source` names the file in error messages. Missing keys keep their defaults;
// anything present but invalid throws UserError with a one-line message.
Config parse_config(std::string_view yaml_text, std::string_view source);

// Reads and parses a YAML file; unreadable files throw UserError.
Config load_config(const std::filesystem::path& file);

// Every key in reference spelling and order, Cradle extensions last; parse_config reads it back
// to an equal Config.
std::string to_yaml(const Config& config);

// Same keys and values as to_yaml; enums as their names.
nlohmann::json to_json(const Config& config);

// Every accepted key, in the order to_yaml writes them.
std::span<const std::string> config_keys();

// Canonical names, as written in YAML and JSON.
std::string_view behavior_name(Behavior behavior);
std::string_view scene_name(SceneKind scene);
std::string_view actuation_model_name(ActuationModel model);
std::string_view touch_function_name(TouchFunction function);
std::string_view touch_response_name(TouchResponse response);

// Name -> enum; nullopt for unknown names. Behaviour also accepts "selftouch" and "handregard".
std::optional<Behavior> behavior_from_name(std::string_view name);
std::optional<SceneKind> scene_from_name(std::string_view name);
std::optional<ActuationModel> actuation_model_from_name(std::string_view name);
std::optional<TouchFunction> touch_function_from_name(std::string_view name);
std::optional<TouchResponse> touch_response_from_name(std::string_view name);

}  // namespace cradle

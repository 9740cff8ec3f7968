#include "tma/tma_env.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/error.h"

namespace cradle::tma {
namespace {

constexpr const char* kStumpId = "parametric-continuous-stump-tracks-v0";
constexpr const char* kParkourId = "parametric-continuous-parkour-v0";

// A number for an error message: short (std::to_string writes 1e300 with 301 digits, 1e-9 as 0).
std::string number_text(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.10g", v);
  return text;
}

// Checks one task value: finite and within [lo, hi].
double checked(const std::string& name, double v, double lo, double hi) {
  if (!std::isfinite(v) || v < lo || v > hi) {
    throw UserError("task parameter " + name + " = " + number_text(v) +
                    " is out of range (expected a finite value in [" + number_text(lo) + ", " +
                    number_text(hi) + "])");
  }
  return v;
}

double single(const TaskParam& p, double lo, double hi) {
  if (p.second.size() != 1) {
    throw UserError("task parameter " + p.first + " takes 1 value (got " +
                    std::to_string(p.second.size()) + ")");
  }
  return checked(p.first, p.second[0], lo, hi);
}

// A (mean, std) pair: the mean within [lo, hi], the std within [0, std_hi].
std::array<double, 2> pair(const TaskParam& p, double lo, double hi, double std_hi) {
  if (p.second.size() != 2) {
    throw UserError("task parameter " + p.first + " takes 2 values, mean and std (got " +
                    std::to_string(p.second.size()) + ")");
  }
  return {checked(p.first + " mean", p.second[0], lo, hi),
          checked(p.first + " std", p.second[1], 0, std_hi)};
}

}  // namespace

EnvId parse_env_id(std::string_view name) {
  if (name == kStumpId || name == "stump-tracks") return EnvId::kStumpTracks;
  if (name == kParkourId || name == "parkour") return EnvId::kParkour;
  throw UserError("unknown TeachMyAgent env '" + std::string(name) + "' (expected " + kStumpId +
                  ", " + kParkourId + ", stump-tracks or parkour)");
}

std::string_view env_id_name(EnvId id) { return id == EnvId::kStumpTracks ? kStumpId : kParkourId; }

const std::vector<std::string>& option_names() {
  static const std::vector<std::string> names = {
      "motors_torque",          "nb_of_bodies",      "nb_pairs_of_legs", "nb_steps_under_water",
      "nb_steps_outside_water", "CPPN_weights_path", "input_CPPN_dim",   "ceiling_offset",
      "ceiling_clip_offset",    "lidars_type",       "water_clip",       "movable_creepers"};
  return names;
}

namespace {

// A finite number, or a one-line error naming the option and what it takes.
double number_option(std::string_view name, std::string_view text, const std::string& expected) {
  const std::string s(text);
  double v = 0;
  try {
    size_t used = 0;
    v = std::stod(s, &used);
    if (used != s.size()) throw std::invalid_argument(s);
  } catch (const std::exception&) {
    throw UserError("option " + std::string(name) + " = '" + s + "' is not a number (expected " +
                    expected + ")");
  }
  if (!std::isfinite(v)) {
    throw UserError("option " + std::string(name) + " = " + s + " (expected " + expected + ")");
  }
  return v;
}

// An integer within [lo, hi]; an integral float ("600.0", as the reference's run.py parses these
// flags) is accepted.
int int_option(std::string_view name, std::string_view text, int lo, int hi) {
  const std::string expected =
      "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  const double v = number_option(name, text, expected);
  if (v != std::floor(v) || v < lo || v > hi) {
    throw UserError("option " + std::string(name) + " = " + std::string(text) + " (expected " +
                    expected + ")");
  }
  return static_cast<int>(v);
}

}  // namespace

void set_option(TmaOptions& o, std::string_view name, std::string_view value) {
  constexpr int kMaxSteps = 1000000000;
  if (name == "motors_torque") {
    const double v = number_option(name, value, "a finite torque >= 0");
    if (v < 0) throw UserError("option motors_torque = " + std::string(value) + " (expected >= 0)");
    o.motors_torque = v;
  } else if (name == "nb_of_bodies") {
    o.nb_of_bodies = int_option(name, value, 1, 100);
  } else if (name == "nb_pairs_of_legs") {
    o.nb_pairs_of_legs = int_option(name, value, 1, 50);
  } else if (name == "nb_steps_under_water") {
    o.nb_steps_under_water = int_option(name, value, 0, kMaxSteps);
  } else if (name == "nb_steps_outside_water") {
    o.nb_steps_outside_water = int_option(name, value, 0, kMaxSteps);
  } else if (name == "CPPN_weights_path") {
    if (value.empty()) throw UserError("option CPPN_weights_path is empty (expected a file path)");
    o.cppn_weights_path = std::string(value);
  } else if (name == "input_CPPN_dim") {
    o.input_cppn_dim = int_option(name, value, 1, 64);
  } else if (name == "ceiling_offset") {
    o.ceiling_offset = number_option(name, value, "a finite number");
  } else if (name == "ceiling_clip_offset") {
    o.ceiling_clip_offset = number_option(name, value, "a finite number");
  } else if (name == "lidars_type") {
    o.lidars = std::string(value);  // checked with the body (down, up or full)
  } else if (name == "water_clip") {
    o.water_clip = number_option(name, value, "a finite positive number");
  } else if (name == "movable_creepers") {
    if (value == "true" || value == "True" || value == "1") {
      o.movable_creepers = true;
    } else if (value == "false" || value == "False" || value == "0") {
      o.movable_creepers = false;
    } else {
      throw UserError("option movable_creepers = '" + std::string(value) +
                      "' (expected true or false)");
    }
  } else {
    std::string known;
    for (const std::string& n : option_names()) known += (known.empty() ? "" : ", ") + n;
    throw UserError("unknown TeachMyAgent option '" + std::string(name) +
                    "' (expected one of: " + known + ")");
  }
}

TmaEnv::TmaEnv(const TmaOptions& options, std::shared_ptr<const Cppn> cppn)
    : options_(options), cppn_(std::move(cppn)) {
  body_ = &embodiment(options_.body);
  check_body_options();
  if (options_.max_episode_steps < 1) {
    throw UserError("max_episode_steps = " + std::to_string(options_.max_episode_steps) +
                    " (expected >= 1)");
  }
  if (!std::isfinite(options_.water_clip) || options_.water_clip <= 0) {
    throw UserError("water_clip must be a finite positive number");
  }
  water_.max_push = options_.water_clip;
  const bool parkour = options_.env == EnvId::kParkour;
  // Lidar fan: Stump Tracks always looks down; Parkour picks by body kind as the reference's
  // run.py does (walkers down, climbers up, others keep the constructor default, full).
  std::string lidars = options_.lidars;
  if (lidars.empty()) {
    lidars = !parkour || body_->kind == BodyKind::kWalker
                 ? "down"
                 : (body_->kind == BodyKind::kClimber ? "up" : "full");
  }
  if (lidars == "down") {
    lidar_type_ = LidarType::kDown;
  } else if (lidars == "up") {
    lidar_type_ = LidarType::kUp;
  } else if (lidars == "full") {
    lidar_type_ = LidarType::kFull;
  } else {
    throw UserError("unknown lidar type '" + lidars + "' (expected down, up or full)");
  }
  // The millipede is as wide as its segments (20 px each); every other body has a fixed width.
  const double width =
      body_->name == "millipede" ? 20 / kScale * options_.nb_of_bodies.value_or(4) : body_->width;
  startpad_ = std::max<double>(kStartpad, width / kTerrainStep + 5);
  if (parkour && !cppn_) {
    if (options_.cppn_weights_path.empty() && options_.input_cppn_dim != 3) {
      throw UserError("input_CPPN_dim = " + std::to_string(options_.input_cppn_dim) +
                      " needs CPPN_weights_path (the shipped CPPN takes 3 inputs)");
    }
    cppn_ = std::make_shared<const Cppn>(options_.cppn_weights_path.empty()
                                             ? data_dir() / "ground_ceiling_cppn.f32"
                                             : std::filesystem::path(options_.cppn_weights_path),
                                         2, options_.input_cppn_dim);
  }
  if (parkour && cppn_->inputs() != options_.input_cppn_dim) {
    throw UserError(
        "the CPPN takes " + std::to_string(cppn_->inputs()) +
        " inputs (expected input_CPPN_dim = " + std::to_string(options_.input_cppn_dim) + ")");
  }
  parkour_task_.input_vector.assign(options_.input_cppn_dim, 0.0);
  reset(0);
  action_size_ = agent_.action_size();
}

TmaEnv::~TmaEnv() {
  // The world goes first: its destructor must not call back into a half-destroyed env.
  if (world_) world_->SetContactListener(nullptr);
  world_.reset();
}

void TmaEnv::check_body_options() {
  const std::string& body = options_.body;
  const BodyKind kind = body_->kind;
  auto refuse = [&](const char* option, const std::string& takes) {
    throw UserError("option " + std::string(option) + " does not apply to " + body + " (" + takes +
                    ")");
  };
  if (options_.nb_of_bodies && body != "millipede") refuse("nb_of_bodies", "millipede only");
  if (options_.nb_pairs_of_legs && body != "spider") refuse("nb_pairs_of_legs", "spider only");
  if (options_.nb_steps_under_water && kind != BodyKind::kWalker && kind != BodyKind::kClimber) {
    refuse("nb_steps_under_water", "walkers and climbers only");
  }
  if (options_.nb_steps_outside_water && kind != BodyKind::kSwimmer) {
    refuse("nb_steps_outside_water", "swimmers (fish) only");
  }
  if (options_.motors_torque &&
      !(std::isfinite(*options_.motors_torque) && *options_.motors_torque >= 0)) {
    throw UserError("option motors_torque must be a finite torque >= 0");
  }
  if (options_.env == EnvId::kStumpTracks) {
    // The Stump Tracks env has no CPPN nor ceiling (the reference's constructor refuses them).
    if (!options_.cppn_weights_path.empty()) refuse("CPPN_weights_path", "Parkour only");
    if (options_.input_cppn_dim != 3) refuse("input_CPPN_dim", "Parkour only");
    if (options_.ceiling_offset != 200) refuse("ceiling_offset", "Parkour only");
    if (options_.ceiling_clip_offset != 0) refuse("ceiling_clip_offset", "Parkour only");
  }
  if (!std::isfinite(options_.ceiling_offset) || !std::isfinite(options_.ceiling_clip_offset)) {
    throw UserError("options ceiling_offset and ceiling_clip_offset must be finite numbers");
  }
  if (kind == BodyKind::kWalker || kind == BodyKind::kClimber) {
    under_water_limit_ = options_.nb_steps_under_water.value_or(kSurviveSteps);
  } else if (kind == BodyKind::kSwimmer) {
    outside_water_limit_ = options_.nb_steps_outside_water.value_or(kSurviveSteps);
  }
}

void TmaEnv::set_stump_task(const StumpTask& task) {
  checked("stump_height", task.stump_height, -3, 9);
  checked("obstacle_spacing", task.obstacle_spacing, 0, 10);
  if (task.stump_width) {
    checked("stump_width mean", (*task.stump_width)[0], 0, 10);
    checked("stump_width std", (*task.stump_width)[1], 0, 10);
  }
  if (task.stump_rot) {
    checked("stump_rot mean", (*task.stump_rot)[0], 0, 2 * std::numbers::pi);
    checked("stump_rot std", (*task.stump_rot)[1], 0, 2 * std::numbers::pi);
  }
  checked("roughness", task.roughness, 0, 10);
  stump_task_ = task;
}

void TmaEnv::set_parkour_task(const ParkourTask& task) {
  if (static_cast<int>(task.input_vector.size()) != options_.input_cppn_dim) {
    throw UserError("task parameter input_vector takes " + std::to_string(options_.input_cppn_dim) +
                    " values (got " + std::to_string(task.input_vector.size()) +
                    "; input_CPPN_dim sets the size)");
  }
  for (double v : task.input_vector) checked("input_vector", v, -1, 1);
  checked("water_level", task.water_level, 0, 1);
  if (task.creepers_width) checked("creepers_width", *task.creepers_width, 0, 5);
  if (task.creepers_height) checked("creepers_height", *task.creepers_height, 0, 10);
  checked("creepers_spacing", task.creepers_spacing, 0, 10);
  if (!std::isfinite(task.terrain_cppn_scale) || task.terrain_cppn_scale <= 1 ||
      task.terrain_cppn_scale > 100) {
    throw UserError("task parameter terrain_cppn_scale = " + number_text(task.terrain_cppn_scale) +
                    " is out of range (expected (1, 100])");
  }
  parkour_task_ = task;
}

void TmaEnv::set_environment(const std::vector<TaskParam>& params) {
  if (options_.env == EnvId::kStumpTracks) {
    StumpTask task = stump_task_;
    for (const TaskParam& p : params) {
      if (p.first == "stump_height") {
        task.stump_height = single(p, -3, 9);
      } else if (p.first == "obstacle_spacing") {
        task.obstacle_spacing = single(p, 0, 10);
      } else if (p.first == "stump_width") {
        task.stump_width = pair(p, 0, 10, 10);
      } else if (p.first == "stump_rot") {
        task.stump_rot = pair(p, 0, 2 * std::numbers::pi, 2 * std::numbers::pi);
      } else if (p.first == "roughness") {
        task.roughness = single(p, 0, 10);
      } else {
        throw UserError("unknown Stump Tracks task parameter '" + p.first +
                        "' (expected stump_height, obstacle_spacing, stump_width, stump_rot or "
                        "roughness)");
      }
    }
    set_stump_task(task);
    return;
  }
  ParkourTask task = parkour_task_;
  for (const TaskParam& p : params) {
    if (p.first == "input_vector") {
      const int dim = options_.input_cppn_dim;
      if (static_cast<int>(p.second.size()) != dim) {
        throw UserError("task parameter input_vector takes " + std::to_string(dim) +
                        " values (got " + std::to_string(p.second.size()) + ")");
      }
      task.input_vector.resize(dim);
      for (int k = 0; k < dim; ++k)
        task.input_vector[k] = checked("input_vector", p.second[k], -1, 1);
    } else if (p.first == "water_level") {
      task.water_level = single(p, 0, 1);
    } else if (p.first == "creepers_width") {
      task.creepers_width = single(p, 0, 5);
    } else if (p.first == "creepers_height") {
      task.creepers_height = single(p, 0, 10);
    } else if (p.first == "creepers_spacing") {
      task.creepers_spacing = single(p, 0, 10);
    } else if (p.first == "terrain_cppn_scale") {
      task.terrain_cppn_scale = single(p, 1.000001, 100);
    } else {
      throw UserError("unknown Parkour task parameter '" + p.first +
                      "' (expected input_vector, water_level, creepers_width, creepers_height, "
                      "creepers_spacing or terrain_cppn_scale)");
    }
  }
  set_parkour_task(task);
}

double TmaEnv::finish_x() const {
  return options_.env == EnvId::kStumpTracks ? (kTerrainLength - 10) * kTerrainStep
                                             : (kTerrainLength + startpad_ - 5) * kTerrainStep;
}

WorldPoint TmaEnv::spawn() const {
  const double x = kTerrainStep * startpad_ / 2;
  const double y = options_.env == EnvId::kStumpTracks && body_->old_morphology
                       ? kTerrainHeight + 2 * body_->leg_h
                       : kTerrainHeight + body_->center_height;
  return WorldPoint{x, y};
}

std::span<const double> TmaEnv::reset(std::optional<std::uint64_t> seed) {
  if (seed) rng_.seed_with(*seed);
  const bool parkour = options_.env == EnvId::kParkour;
  // A fresh world per episode: no state (proxy ids, contact order) leaks between episodes.
  if (world_) world_->SetContactListener(nullptr);
  world_ = std::make_unique<b2World>(b2Vec2(0, -10));
  agent_ = Agent{};
  listener_.clear();
  listener_.configure(parkour, &agent_);
  world_->SetContactListener(&listener_);
  prev_shaping_.reset();
  under_water_ = outside_water_ = 0;
  dead_ = false;
  steps_ = 0;
  episode_return_ = 0;

  // Terrain, clouds, then the agent with its initial push.
  if (parkour) {
    build_parkour(*world_, parkour_task_, *cppn_, startpad_, options_.movable_creepers, rng_, tags_,
                  scene_, options_.ceiling_offset, options_.ceiling_clip_offset);
  } else {
    build_stump_tracks(*world_, stump_task_, startpad_, rng_, tags_, scene_);
  }
  make_clouds(rng_, scene_);
  const double force = rng_.uniform(-5, 5);
  const WorldPoint p = spawn();
  build_agent(options_.body, *world_, p.x, p.y, body_->kind == BodyKind::kSwimmer ? 0.0 : force,
              /*stump_tracks=*/!parkour, agent_,
              BodyOptions{.nb_of_bodies = options_.nb_of_bodies.value_or(4),
                          .nb_pairs_of_legs = options_.nb_pairs_of_legs.value_or(2)});
  if (options_.motors_torque) agent_.torque = *options_.motors_torque;
  const int n_actions = agent_.action_size();
  obs_.assign((parkour ? 6 + 2 * kLidars : 4 + kLidars) + agent_.state_size(), 0.0);
  action_.assign(n_actions, 0.0);

  std::vector<double> first(n_actions, 0.0);
  if (parkour && agent_.kind == BodyKind::kClimber) {
    // Hang from the ceiling: sensors to the ceiling height, the body shifted by the same amount,
    // then a few steps with both grasp commands on so the grips form.
    const int n_sensors = static_cast<int>(agent_.sensors.size());
    double dy = 0;
    for (int i = 0; i < n_sensors; ++i) {
      first[n_actions - 1 - i] = 1;
      b2Body* s = agent_.sensors[n_sensors - 1 - i].body;
      const double target = kTerrainHeight + scene_.ceiling_offset;
      if (dy == 0) dy = target - s->GetPosition().y;
      s->SetTransform(b2Vec2(s->GetPosition().x, static_cast<float>(target)), s->GetAngle());
    }
    for (b2Body* b : agent_.parts) {
      b->SetTransform(b2Vec2(b->GetPosition().x, static_cast<float>(b->GetPosition().y + dy)),
                      b->GetAngle());
    }
    for (int k = 0; k < 5; ++k) step_raw(first.data());
  }
  step_raw(first.data());
  // Parkour forgets the reset steps' counters and return (but not prev_shaping nor a fatal
  // contact); Stump Tracks keeps the reset step's reward in the return.
  if (parkour) {
    under_water_ = outside_water_ = 0;
    episode_return_ = 0;
  }
  steps_ = 0;
  return obs_;
}

TmaStep TmaEnv::step(std::span<const double> action) {
  if (static_cast<int>(action.size()) != action_size_) {
    throw UserError("action has " + std::to_string(action.size()) + " values (expected " +
                    std::to_string(action_size_) + " for " + options_.body + ")");
  }
  for (size_t i = 0; i < action.size(); ++i) {
    if (!std::isfinite(action[i])) {
      throw UserError("action[" + std::to_string(i) + "] is not finite (expected a number in " +
                      "[-1, 1])");
    }
  }
  TmaStep out = step_raw(action.data());
  ++steps_;
  out.truncated = !out.terminated && steps_ >= options_.max_episode_steps;
  return out;
}

TmaStep TmaEnv::step_raw(const double* action) {
  const bool parkour = options_.env == EnvId::kParkour;
  const bool climber = agent_.kind == BodyKind::kClimber;
  // A drowned walker / climber or a stranded fish stops acting (permanently: counters freeze).
  const bool dead = parkour && ((outside_water_limit_ && outside_water_ > *outside_water_limit_) ||
                                (under_water_limit_ && under_water_ > *under_water_limit_));
  dead_ = dead;
  const int n = static_cast<int>(action_.size());
  for (int i = 0; i < n; ++i) action_[i] = dead ? 0.0 : action[i];

  agent_.activate_motors(action_);
  if (climber) climbing_before_step(*world_, agent_, action_.data() + agent_.motors.size());
  box2d23_limits(*world_);
  world_->Step(static_cast<float>(1.0 / kFps), kVelocityIterations, kPositionIterations);
  if (climber) climbing_after_step(*world_, agent_);
  if (parkour) apply_water_forces(listener_.water_pairs, world_->GetGravity(), water_);

  cast_and_observe(dead);

  // Reward: progress of the head (minus its tilt), minus the torque cost.
  const b2Body* head = agent_.head;
  const double x = head->GetPosition().x;
  double shaping = 130.0 * x / kScale;
  if (!agent_.remove_head_angle) shaping -= 5.0 * std::abs(obs_[0]);
  TmaStep out;
  if (prev_shaping_) out.reward = shaping - *prev_shaping_;
  prev_shaping_ = shaping;
  for (int i = 0; i < n; ++i) {
    out.reward -= agent_.torque_penalty * 80.0 * std::clamp(std::abs(action_[i]), 0.0, 1.0);
  }
  if (listener_.critical || x < 0) {
    out.reward = -100;
    out.terminated = true;
  }
  if (x > finish_x()) out.terminated = true;
  episode_return_ += out.reward;
  out.success = episode_return_ > kSuccessReturn;
  return out;
}

void TmaEnv::cast_and_observe(bool dead) {
  const bool parkour = options_.env == EnvId::kParkour;
  const b2Body* head = agent_.head;
  const b2Vec2 pos = head->GetPosition();
  const b2Vec2 vel = head->GetLinearVelocity();
  const std::uint16_t mask = head->GetFixtureList()->GetFilterData().maskBits;
  cast_lidars(*world_, pos, mask, lidar_type_, lidars_);
  const bool under = pos.y <= scene_.water_y;
  if (parkour && !dead) {
    if (under) {
      ++under_water_;
      outside_water_ = 0;
    } else {
      ++outside_water_;
      under_water_ = 0;
    }
  }
  double* o = obs_.data();
  *o++ = head->GetAngle();
  *o++ = 2.0 * head->GetAngularVelocity() / kFps;
  *o++ = 0.3 * vel.x * (kViewportW / kScale) / kFps;
  *o++ = 0.3 * vel.y * (kViewportH / kScale) / kFps;
  if (parkour) {
    *o++ = under ? 1.0 : 0.0;
    *o++ = dead ? 1.0 : 0.0;
  }
  o += agent_.write_state(o);
  for (const LidarReading& r : lidars_) *o++ = r.fraction;
  if (parkour) {
    for (const LidarReading& r : lidars_) *o++ = r.code;
  }
}

}  // namespace cradle::tma

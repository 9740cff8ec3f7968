#include "tma/tma_env.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "core/error.h"

namespace cradle::tma {
namespace {

constexpr const char* kStumpId = "parametric-continuous-stump-tracks-v0";
constexpr const char* kParkourId = "parametric-continuous-parkour-v0";

// Checks one task value: finite and within [lo, hi].
double checked(const std::string& name, double v, double lo, double hi) {
  if (!std::isfinite(v) || v < lo || v > hi) {
    throw UserError("task parameter " + name + " = " + std::to_string(v) +
                    " is out of range (expected a finite value in [" + std::to_string(lo) + ", " +
                    std::to_string(hi) + "])");
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

TmaEnv::TmaEnv(const TmaOptions& options, std::shared_ptr<const Cppn> cppn)
    : options_(options), cppn_(std::move(cppn)) {
  body_ = &embodiment(options_.body);
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
  startpad_ = std::max<double>(kStartpad, body_->width / kTerrainStep + 5);
  if (parkour && !cppn_) {
    cppn_ = std::make_shared<const Cppn>(data_dir() / "ground_ceiling_cppn.f32", 2);
  }
  reset(0);
  action_size_ = agent_.action_size();
}

TmaEnv::~TmaEnv() {
  // The world goes first: its destructor must not call back into a half-destroyed env.
  if (world_) world_->SetContactListener(nullptr);
  world_.reset();
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
  for (double v : task.input_vector) checked("input_vector", v, -1, 1);
  checked("water_level", task.water_level, 0, 1);
  if (task.creepers_width) checked("creepers_width", *task.creepers_width, 0, 5);
  if (task.creepers_height) checked("creepers_height", *task.creepers_height, 0, 10);
  checked("creepers_spacing", task.creepers_spacing, 0, 10);
  if (!std::isfinite(task.terrain_cppn_scale) || task.terrain_cppn_scale <= 1 ||
      task.terrain_cppn_scale > 100) {
    throw UserError(
        "task parameter terrain_cppn_scale = " + std::to_string(task.terrain_cppn_scale) +
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
      if (p.second.size() != 3) {
        throw UserError("task parameter input_vector takes 3 values (got " +
                        std::to_string(p.second.size()) + ")");
      }
      for (int k = 0; k < 3; ++k)
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
                  scene_);
  } else {
    build_stump_tracks(*world_, stump_task_, startpad_, rng_, tags_, scene_);
  }
  make_clouds(rng_, scene_);
  const double force = rng_.uniform(-5, 5);
  const WorldPoint p = spawn();
  build_agent(options_.body, *world_, p.x, p.y, body_->kind == BodyKind::kSwimmer ? 0.0 : force,
              /*stump_tracks=*/!parkour, agent_);
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
  const bool dead =
      parkour && ((agent_.kind == BodyKind::kSwimmer && outside_water_ > kSurviveSteps) ||
                  ((agent_.kind == BodyKind::kWalker || climber) && under_water_ > kSurviveSteps));
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

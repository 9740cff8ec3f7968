#include "envs/babybench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <string_view>

#include "core/error.h"
#include "envs/action_check.h"

namespace cradle::envs {
namespace {

// The cubes' distance from MIMo a curriculum may set (m).
constexpr double kCubeDistance[2] = {0.1, 0.8};

using Clock = std::chrono::steady_clock;

double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

// The senses a config turns on.
MimoSenses config_senses(const BabyBenchAssets& assets) {
  const Config& c = assets.config;
  return {.proprio = {.velocity = c.proprio_velocity,
                      .torque = c.proprio_torque,
                      .limits = c.proprio_limits,
                      .actuation = c.proprio_actuation},
          .touch = assets.touch.get(),
          .vision_resolution = c.vision_active ? c.vision_resolution : 0,
          .vestibular = c.vestibular_active};
}

// How far a random start may leave one of MIMo's geoms inside the world below him (m).
constexpr double kStartClearance = 0.002;

// Raises MIMo on his free root until none of his geoms is more than kStartClearance inside a
// world geom below it: random joint angles can put a limb through the floor or the mattress, and
// MuJoCo's push-out forces then can make the physics diverge. Only contacts with a mostly
// vertical normal count (lifting cannot resolve a limb through a crib bar); the scenes have
// nothing above MIMo.
void lift_out_of_world(const mjModel* m, mjData* d, int root_joint) {
  const int root_body = m->jnt_bodyid[root_joint];
  const auto on_mimo = [&](int geom) { return m->body_rootid[m->geom_bodyid[geom]] == root_body; };
  for (int pass = 0; pass < 4; ++pass) {
    double depth = 0;
    for (int c = 0; c < d->ncon; ++c) {
      const mjContact& con = d->contact[c];
      if (on_mimo(con.geom1) == on_mimo(con.geom2) || std::abs(con.frame[2]) < 0.7) continue;
      depth = std::max(depth, -con.dist);
    }
    if (depth <= kStartClearance) return;
    d->qpos[m->jnt_qposadr[root_joint] + 2] += depth;
    mj_forward(m, d);
  }
}

}  // namespace

DictSpace babybench_observation_space(const BabyBenchAssets& assets, int actuation_obs_size) {
  return mimo_observation_space(assets.model.get(), config_senses(assets), actuation_obs_size);
}

namespace {

// Lays out the skin and settles the pose of a compiled scene.
std::shared_ptr<const BabyBenchAssets> finish_assets(std::shared_ptr<BabyBenchAssets> assets) {
  const Config& config = assets->config;
  const mjModel* m = assets->model.get();
  if (config.touch_enabled()) {
    senses::TouchOptions touch{
        .body_scales = senses::default_touch_scales(scene::mimo_version_for(config.behavior),
                                                    config.touch_groups, config.touch_scale),
        .function = config.touch_function,
        .response = config.touch_response};
    if (!touch.body_scales.empty()) {
      assets->touch = std::make_unique<senses::Touch>(m, touch);
      assets->touch_layout = skin_layout(*assets->touch);
    }
  }

  // Let the pose settle under zero action (locks already hold from the compiled model on).
  sim::Sim sim(m, config.actuation_model, 1);
  const std::vector<double> zero(sim.actuation().action_space().size(), 0.0);
  for (int i = 0; i < BabyBenchEnv::kSettleSteps; ++i) sim.step(zero);
  sim.save(assets->settled);
  return assets;
}

}  // namespace

std::shared_ptr<const BabyBenchAssets> make_assets(const Config& config) {
  auto assets = std::make_shared<BabyBenchAssets>();
  assets->config = config;
  assets->scene = scene::compose_scene(config);
  assets->model = scene::compile_scene(assets->scene);
  return finish_assets(std::move(assets));
}

std::shared_ptr<const BabyBenchAssets> make_assets(const Config& config,
                                                   const std::filesystem::path& scene_file) {
  auto assets = std::make_shared<BabyBenchAssets>();
  assets->config = config;
  assets->model = scene::load_scene(scene_file);
  return finish_assets(std::move(assets));
}

BabyBenchEnv::BabyBenchEnv(std::shared_ptr<const BabyBenchAssets> assets, std::uint64_t seed)
    : assets_(std::move(assets)),
      core_(assets_->model.get(), assets_->config.actuation_model, assets_->config.frame_skip,
            config_senses(*assets_)),
      task_(make_behaviour(assets_->config, assets_->model.get())),
      contacts_(assets_->model.get()),
      rng_(seed) {
  const mjModel* m = assets_->model.get();
  random_action_.resize(action_space().size());
  for (int j = 0; j < m->njnt; ++j) {
    const char* name = mj_id2name(m, mjOBJ_JOINT, j);
    if (!name || !std::string_view(name).starts_with("robot:")) continue;
    bool held = false;
    for (int e = 0; e < m->neq; ++e) {
      held = held || (m->eq_active[e] && m->eq_type[e] == mjEQ_JOINT && m->eq_obj1id[e] == j);
    }
    if (!held) free_joints_.push_back(j);
  }

  root_joint_ = mj_name2id(m, mjOBJ_JOINT, "mimo_location");
  if (root_joint_ < 0 || m->jnt_type[root_joint_] != mjJNT_FREE) {
    throw UserError("BabyBench scene: MIMo has no free root joint 'mimo_location'");
  }

  task_->declare(info_);
  contacts_.declare(info_);
  overflow_slot_ = info_.declare(kOverflowKey, InfoType::kInt);
  diverged_slot_ = info_.declare(kDivergedKey, InfoType::kInt);
  core_.sim().restore(assets_->settled);
  core_.observe();
}

BabyBenchEnv::~BabyBenchEnv() {
  try {
    close();
  } catch (...) {
    // Destructors must not throw; call close() to see logging errors.
  }
}

void BabyBenchEnv::set_reset_options(const ResetOptions& options) {
  for (const auto& [name, value] : options) {
    // A curriculum's start posture: joints drawn within this share of their range around the
    // settled pose (1: the whole range, as randomize_start).
    if (name == "start_posture_range") {
      if (!(value >= 0 && value <= 1)) {
        throw UserError("reset option start_posture_range must be in [0, 1], not " +
                        std::to_string(value));
      }
      start_posture_range_ = value;
      continue;
    }
    // A curriculum's reach distance: the cubes stack this far from MIMo (cubes scene only).
    if (name == "cube_distance") {
      const mjModel* m = model();
      cube_qpos_.clear();
      for (const char* cube : {"red_cube", "yellow_cube", "blue_cube"}) {
        const int b = mj_name2id(m, mjOBJ_BODY, cube);
        if (b >= 0 && m->body_jntnum[b] == 1)
          cube_qpos_.push_back(m->jnt_qposadr[m->body_jntadr[b]]);
      }
      if (cube_qpos_.size() != 3) {
        throw UserError("reset option cube_distance needs the cubes scene (scene: cubes)");
      }
      if (!(value >= kCubeDistance[0] && value <= kCubeDistance[1])) {
        throw UserError("reset option cube_distance must be in [0.1, 0.8] m, not " +
                        std::to_string(value));
      }
      cube_distance_ = value;
      continue;
    }
    if (name != "randomize_start") {
      throw UserError("reset option '" + name +
                      "' is not a BabyBench one (expected randomize_start, start_posture_range or "
                      "cube_distance)");
    }
    if (value != 0 && value != 1) {
      throw UserError("reset option randomize_start must be 0 or 1, not " + std::to_string(value));
    }
    randomize_start_ = value != 0;
  }
}

const ObservationLayout* BabyBenchEnv::layout(std::string_view key) const {
  return key == kTouchKey && assets_->touch ? &assets_->touch_layout : nullptr;
}

void BabyBenchEnv::close() {
  if (log_ && steps_ > 0 && !skip_record_) log_->record(info_, steps_, score(), log_slot_);
  skip_record_ = true;
  if (log_) log_->flush();
  log_.reset();
}

void BabyBenchEnv::end_episode() {
  if (log_ && !skip_record_) log_->record(info_, steps_, score(), log_slot_);
  skip_record_ = true;
}

std::shared_ptr<TrainingLog> start_training(const BabyBenchAssets& assets, long continue_log) {
  const Config& config = assets.config;
  const std::filesystem::path dir = config.save_dir;
  scene::write_scene(assets.scene, dir / scene::kSceneDirName);
  std::error_code ec;
  std::filesystem::create_directories(dir / "videos", ec);
  return std::make_shared<TrainingLog>(dir / "logs" / "training.jsonl", config.save_logs_every,
                                       continue_log >= 0, std::max(continue_log, 0L));
}

std::unique_ptr<BabyBenchEnv> make_env(const Config& config, bool training, std::uint64_t seed) {
  auto assets = make_assets(config);
  auto env = std::make_unique<BabyBenchEnv>(assets, seed);
  if (training) env->attach_log(start_training(*assets));
  return env;
}

void BabyBenchEnv::reset(std::optional<std::uint64_t> seed) {
  if (log_ && !skip_record_) log_->record(info_, steps_, score(), log_slot_);
  skip_record_ = false;
  if (seed) rng_.seed_with(*seed);
  sim::Sim& sim = core_.sim();
  sim.reset();
  sim.restore(assets_->settled);
  if (randomize_start_ || start_posture_range_ > 0) {
    const mjModel* m = model();
    mjData* d = sim.data();
    const double r = randomize_start_ ? 1.0 : start_posture_range_;
    for (int j : free_joints_) {
      double& q = d->qpos[m->jnt_qposadr[j]];
      const double lo = m->jnt_range[2 * j], hi = m->jnt_range[2 * j + 1];
      q = r == 1.0 ? rng_.uniform(lo, hi) : rng_.uniform(q + r * (lo - q), q + r * (hi - q));
    }
    mj_forward(m, d);
    lift_out_of_world(m, d, root_joint_);
  }
  // The cubes moved together along the line from MIMo's root to the red cube.
  if (cube_distance_ > 0) {
    mjData* d = sim.data();
    const double* root = d->xpos + 3 * model()->jnt_bodyid[root_joint_];
    const double dx = d->qpos[cube_qpos_[0]] - root[0], dy = d->qpos[cube_qpos_[0] + 1] - root[1];
    const double shift = cube_distance_ / std::max(std::hypot(dx, dy), 1e-9) - 1;
    for (int q : cube_qpos_) {
      d->qpos[q] += shift * dx;
      d->qpos[q + 1] += shift * dy;
    }
    mj_forward(model(), d);
  }

  // Random start: a few random actions drawn from the env's own (seeded) generator.
  const Box& space = action_space();
  for (int i = 0; i < kRandomResetSteps; ++i) {
    space.sample(rng_, random_action_);
    sim.step(random_action_);
  }
  steps_ = 0;
  info_.clear();
  task_->reset(core_, info_);
  contacts_.update(sim.data(), info_);
  core_.observe();
}

StepResult BabyBenchEnv::step(std::span<const double> action) {
  check_finite_actions(action);
  core_.step(action, /*contact_forces=*/false);
  core_.observe();

  const Clock::time_point task_start = Clock::now();
  info_.steps = steps_;
  StepResult result;
  result.reward = task_->after_step(core_, info_);
  contacts_.update(core_.data(), info_);
  ++steps_;
  result.truncated = steps_ >= assets_->config.max_episode_steps;
  // A step whose physics overflowed MuJoCo's sizes is wrong: the episode ends there, counted.
  if (const int n = core_.sim().overflows()) {
    info_.add(overflow_slot_, n);
    result.truncated = true;
  }
  // So is one whose physics diverged: MuJoCo restarted it from the model's initial state.
  if (const int n = core_.sim().divergences()) {
    info_.add(diverged_slot_, n);
    result.truncated = true;
  }
  Profile& profile = core_.profile();
  profile.other += seconds(Clock::now() - task_start);
  ++profile.steps;
  return result;
}

std::vector<TaskParameter> babybench_task_parameters(const Config& config) {
  std::vector<TaskParameter> out = {{"start_posture_range", 0, 1}, {"randomize_start", 0, 1}};
  if (config.scene == SceneKind::kCubes)
    out.push_back({"cube_distance", kCubeDistance[0], kCubeDistance[1]});
  return out;
}

}  // namespace cradle::envs

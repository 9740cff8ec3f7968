#include "envs/babybench.h"

#include <algorithm>
#include <filesystem>
#include <string_view>

#include "core/error.h"
#include "envs/action_check.h"

namespace cradle::envs {
namespace {

senses::ProprioOptions proprio_options(const Config& c) {
  return {.velocity = c.proprio_velocity,
          .torque = c.proprio_torque,
          .limits = c.proprio_limits,
          .actuation = c.proprio_actuation};
}

double seconds(std::chrono::steady_clock::duration d) {
  return std::chrono::duration<double>(d).count();
}

}  // namespace

DictSpace babybench_observation_space(const BabyBenchAssets& assets, int actuation_obs_size) {
  const Config& c = assets.config;
  const mjModel* m = assets.model.get();
  // Keys in the reference's order: proprioception, touch, eyes, vestibular.
  DictSpace space;
  space.entries.emplace_back(
      BabyBenchEnv::kProprioKey,
      senses::Proprioception(m, proprio_options(c), actuation_obs_size).space());
  if (assets.touch) space.entries.emplace_back(BabyBenchEnv::kTouchKey, assets.touch->space());
  if (c.vision_active) {
    const Box eye = senses::Eyes::space_for(c.vision_resolution);
    space.entries.emplace_back(BabyBenchEnv::kEyeLeftKey, eye);
    space.entries.emplace_back(BabyBenchEnv::kEyeRightKey, eye);
  }
  if (c.vestibular_active) {
    space.entries.emplace_back(BabyBenchEnv::kVestibularKey, senses::Vestibular(m).space());
  }
  return space;
}

ObservationLayout skin_layout(const senses::Touch& touch) {
  ObservationLayout layout{.values_per_item = touch.values_per_sensor()};
  const std::span<const int> geoms = touch.sensor_geoms(), bodies = touch.sensor_bodies();
  layout.groups["geom"].assign(geoms.begin(), geoms.end());
  layout.groups["body"].assign(bodies.begin(), bodies.end());
  return layout;
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
      sim_(assets_->model.get(), assets_->config.actuation_model, assets_->config.frame_skip),
      proprio_(assets_->model.get(), proprio_options(assets_->config),
               sim_.actuation().observation_size()),
      task_(make_behaviour(assets_->config, assets_->model.get())),
      contacts_(assets_->model.get()),
      observation_space_(
          babybench_observation_space(*assets_, sim_.actuation().observation_size())),
      obs_(observation_space_),
      proprio_index_(key_index(kProprioKey)),
      touch_index_(key_index(kTouchKey)),
      eye_left_index_(key_index(kEyeLeftKey)),
      eye_right_index_(key_index(kEyeRightKey)),
      vestibular_index_(key_index(kVestibularKey)),
      rng_(seed) {
  const Config& c = assets_->config;
  const mjModel* m = assets_->model.get();
  if (c.vestibular_active) vestibular_.emplace(m);
  if (c.vision_active) eyes_ = std::make_unique<senses::Eyes>(m, c.vision_resolution);
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

  task_->declare(info_);
  contacts_.declare(info_);
  overflow_slot_ = info_.declare(kOverflowKey, InfoType::kInt);
  sim_.restore(assets_->settled);
  observe();
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
    if (name != "randomize_start") {
      throw UserError("reset option '" + name +
                      "' is not a BabyBench one (expected randomize_start)");
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

int BabyBenchEnv::key_index(std::string_view key) const {
  for (int i = 0; i < static_cast<int>(observation_space_.entries.size()); ++i) {
    if (observation_space_.entries[i].first == key) return i;
  }
  return -1;
}

void BabyBenchEnv::reset(std::optional<std::uint64_t> seed) {
  if (log_ && !skip_record_) log_->record(info_, steps_, score(), log_slot_);
  skip_record_ = false;
  if (seed) rng_.seed_with(*seed);
  sim_.reset();
  sim_.restore(assets_->settled);
  if (randomize_start_) {
    const mjModel* m = model();
    mjData* d = sim_.data();
    for (int j : free_joints_) {
      d->qpos[m->jnt_qposadr[j]] = rng_.uniform(m->jnt_range[2 * j], m->jnt_range[2 * j + 1]);
    }
    mj_forward(m, d);
  }

  // Random start: a few random actions drawn from the env's own (seeded) generator.
  const Box& space = action_space();
  for (int i = 0; i < kRandomResetSteps; ++i) {
    for (size_t k = 0; k < random_action_.size(); ++k) {
      random_action_[k] = rng_.uniform(space.low[k], space.high[k]);
    }
    sim_.step(random_action_);
  }
  steps_ = 0;
  info_.clear();
  task_->reset(model(), sim_.data(), info_);
  contacts_.update(sim_.data(), info_);
  observe();
}

StepResult BabyBenchEnv::step(std::span<const double> action) {
  check_finite_actions(action);
  const Clock::time_point start = Clock::now();
  sim_.step(action);
  profile_.physics += seconds(Clock::now() - start);
  observe();

  const Clock::time_point task_start = Clock::now();
  info_.steps = steps_;
  StepResult result;
  result.reward = task_->after_step(model(), sim_.data(), info_);
  contacts_.update(sim_.data(), info_);
  ++steps_;
  result.truncated = steps_ >= assets_->config.max_episode_steps;
  // A step whose physics overflowed MuJoCo's sizes is wrong: the episode ends there, counted.
  if (const int n = sim_.overflows()) {
    info_.add(overflow_slot_, n);
    result.truncated = true;
  }
  profile_.other += seconds(Clock::now() - task_start);
  ++profile_.steps;
  return result;
}

void BabyBenchEnv::observe() {
  const mjModel* m = model();
  mjData* d = sim_.data();
  Clock::time_point t = Clock::now();
  auto lap = [&](double& bucket) {
    const Clock::time_point now = Clock::now();
    bucket += seconds(now - t);
    t = now;
  };
  proprio_.read(m, d, sim_.actuation(), obs_.f64(proprio_index_));
  lap(profile_.proprio);
  if (touch_index_ >= 0) {
    touch()->read(m, d, obs_.f32(touch_index_));
    lap(profile_.touch);
  }
  if (eyes_) {
    eyes_->render(m, d, obs_.u8(eye_left_index_), obs_.u8(eye_right_index_));
    lap(profile_.vision);
  }
  if (vestibular_) {
    vestibular_->read(d, obs_.f64(vestibular_index_));
    lap(profile_.vestibular);
  }
}

}  // namespace cradle::envs

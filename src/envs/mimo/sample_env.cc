#include "envs/mimo/sample_env.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "core/error.h"
#include "core/xml.h"
#include "envs/action_check.h"

namespace cradle::envs {
namespace {

using Clock = std::chrono::steady_clock;

double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

}  // namespace

const std::vector<SampleDefinition>& sample_definitions() {
  static const std::vector<SampleDefinition> all = {
      bench_definition(false), bench_definition(true), showroom_definition(), reach_definition(),
      standup_definition(),    selfbody_definition(),  catch_definition(),
  };
  return all;
}

namespace {

std::string joined_names() {
  std::string names;
  for (const std::string& n : sample_env_names()) names += (names.empty() ? "" : ", ") + n;
  return names;
}

}  // namespace

const std::vector<std::string>& sample_env_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const SampleDefinition& d : sample_definitions()) out.push_back(d.name);
    return out;
  }();
  return names;
}

std::string sample_env_id(std::string_view short_name) {
  if (short_name == "reach") return "MIMoReach-v0";
  if (short_name == "standup") return "MIMoStandup-v0";
  if (short_name == "selfbody") return "MIMoSelfBody-v0";
  if (short_name == "catch") return "MIMoCatch-v0";
  throw UserError("unknown env '" + std::string(short_name) +
                  "'; expected one of reach, standup, selfbody, catch");
}

scene::WorldFragments sample_floor() {
  scene::WorldFragments w;
  w.assets =
      "<texture type=\"skybox\" builtin=\"gradient\" rgb1=\".4 .6 .8\" rgb2=\"0 0 0\" "
      "width=\"100\" height=\"100\"/>\n"
      "<texture name=\"texplane\" type=\"2d\" builtin=\"checker\" rgb1=\".2 .3 .4\" "
      "rgb2=\".1 .15 .2\" width=\"100\" height=\"100\"/>\n";
  w.materials = {{"matplane", "texplane", "texrepeat=\"1 1\" texuniform=\"true\""}};
  w.worldbody =
      "<light directional=\"false\" diffuse=\".4 .4 .4\" specular=\"0 0 0\" pos=\"0 0 10\" "
      "dir=\"0 0 -1\" castshadow=\"false\"/>\n"
      "<light directional=\"false\" diffuse=\".6 .6 .6\" specular=\".2 .2 .2\" pos=\"2 -2 4\" "
      "dir=\"-1 1 -2\"/>\n"
      "<geom name=\"floor\" type=\"plane\" pos=\"0 0 0\" size=\"0 0 .25\" material=\"matplane\" "
      "condim=\"3\"/>\n";
  return w;
}

std::string look_at_camera(const std::array<double, 3>& lookat, double distance, double azimuth,
                           double elevation) {
  const double az = azimuth * std::numbers::pi / 180, el = elevation * std::numbers::pi / 180;
  // MuJoCo's free camera: forward from azimuth about z and elevation (negative looks down).
  const double f[3] = {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
  const double pos[3] = {lookat[0] - distance * f[0], lookat[1] - distance * f[1],
                         lookat[2] - distance * f[2]};
  // Camera x = right = forward x up(z), camera y = right x forward.
  const double r[3] = {std::sin(az), -std::cos(az), 0};
  const double u[3] = {r[1] * f[2] - r[2] * f[1], r[2] * f[0] - r[0] * f[2],
                       r[0] * f[1] - r[1] * f[0]};
  return "<camera name=\"view\" pos=\"" + nums({pos[0], pos[1], pos[2]}) + "\" xyaxes=\"" +
         nums({r[0], r[1], r[2], u[0], u[1], u[2]}) + "\" fovy=\"45\"/>\n";
}

int qpos_address(const mjModel* m, const std::string& joint) {
  const int id = mj_name2id(m, mjOBJ_JOINT, joint.c_str());
  if (id < 0) throw std::runtime_error("sample env: no joint '" + joint + "'");
  return m->jnt_qposadr[id];
}

int body_id(const mjModel* m, const std::string& body) {
  const int id = mj_name2id(m, mjOBJ_BODY, body.c_str());
  if (id < 0) throw std::runtime_error("sample env: no body '" + body + "'");
  return id;
}

std::shared_ptr<const SampleAssets> make_sample_assets(std::string_view name,
                                                       const SampleOptions& options) {
  const auto& all = sample_definitions();
  const auto it = std::ranges::find(all, name, &SampleDefinition::name);
  if (it == all.end()) {
    throw UserError("unknown sample env '" + std::string(name) + "'; expected one of " +
                    joined_names());
  }
  if (options.vision_resolution < 1 || options.render_size < 1) {
    throw UserError("sample env: vision_resolution and render_size must be positive");
  }
  // Catch's options on another env would silently do nothing.
  if (it->name != "MIMoCatch-v0") {
    const std::pair<bool, const char*> catch_only[] = {
        {!options.action_penalty, "action_penalty"},
        {options.jitter, "jitter"},
        {options.position_inaccurate, "position_inaccurate"},
        {options.palm_up, "palm_up"}};
    for (const auto& [set, option] : catch_only) {
      if (set) {
        throw UserError("sample env option '" + std::string(option) + "' applies to " +
                        "MIMoCatch-v0 only, not " + it->name);
      }
    }
  }
  auto assets = std::make_shared<SampleAssets>();
  assets->definition = *it;
  assets->options = options;
  const SampleDefinition& def = assets->definition;
  assets->actuation = options.actuation.value_or(def.actuation);
  assets->goals_in_observation = options.goals_in_observation.value_or(def.goals_in_observation);
  assets->done_active = options.done_active.value_or(def.done_active);

  // The task's scene, the actuation model's actuators and a free-view camera for videos.
  scene::Composition c = def.scene(options);
  c.comment = "Generated by Cradle " CRADLE_VERSION ": " + def.name;
  // No shadow maps: with software rendering they cost ~100 ms per eye image pair.
  c.visual = "<quality shadowsize=\"0\"/>\n" + c.visual;
  c.emit.actuation = assets->actuation;
  c.offscreen = std::max({c.offscreen, options.render_size, 2 * options.vision_resolution});
  scene::WorldFragments camera;
  camera.worldbody = look_at_camera(def.camera_lookat, def.camera_distance, def.camera_azimuth,
                                    def.camera_elevation);
  c.worlds.push_back(std::move(camera));
  assets->scene = scene::compose(c);
  assets->model = scene::compile_scene(assets->scene);
  const mjModel* m = assets->model.get();
  assets->camera = mj_name2id(m, mjOBJ_CAMERA, "view");

  // The start state: the XML state with the task's initial positions.
  sim::Sim sim(m, assets->actuation, def.frame_skip);
  if (def.initial_state) {
    def.initial_state(m, sim.data());
    mj_forward(m, sim.data());
  }
  sim.save(assets->init);

  if (!def.touch.empty()) {
    assets->touch =
        std::make_unique<senses::Touch>(m, senses::TouchOptions{.body_scales = def.touch});
    assets->touch_layout = skin_layout(*assets->touch);
  }
  return assets;
}

std::unique_ptr<MimoEnv> make_sample_env(std::shared_ptr<const SampleAssets> assets,
                                         std::uint64_t seed) {
  auto env = std::make_unique<MimoEnv>(std::move(assets), seed);
  env->reset(seed);
  return env;
}

std::unique_ptr<MimoEnv> make_sample_env(std::string_view name, const SampleOptions& options,
                                         std::uint64_t seed) {
  return make_sample_env(make_sample_assets(name, options), seed);
}

void SampleTask::declare(Info& info) {
  success_slot_ = info.declare("is_success", InfoType::kBool);
  failure_slot_ = info.declare("is_failure", InfoType::kBool);
}

void SampleTask::set_outcome(Info& info, bool success, bool failure) const {
  info.set(success_slot_, success);
  info.set(failure_slot_, failure);
}

namespace {

// The senses of a sample env: the task's, with the reference's proprioception.
MimoSenses sample_senses(const SampleAssets& assets) {
  const SampleDefinition& def = assets.definition;
  return {.extra_proprio = def.extra_observation,
          .touch = assets.touch.get(),
          .vision_resolution = def.vision ? assets.options.vision_resolution : 0,
          .vestibular = def.vestibular,
          .goals = assets.goals_in_observation,
          .goal_size = def.goal_size};
}

}  // namespace

MimoEnv::MimoEnv(std::shared_ptr<const SampleAssets> assets, std::uint64_t seed)
    : assets_(std::move(assets)),
      core_(assets_->model.get(), assets_->actuation, assets_->definition.frame_skip,
            sample_senses(*assets_)),
      task_(assets_->definition.make(core_, assets_->options)),
      goal_(assets_->definition.goal_size, 0.0),
      rng_(seed) {
  task_->declare(info_);
  success_slot_ = info_.find("is_success");
  failure_slot_ = info_.find("is_failure");
  core_.sim().restore(assets_->init);
}

void set_task_options(std::string_view env, std::span<const TaskOption> known,
                      const ResetOptions& options) {
  for (const auto& [name, value] : options) {
    const auto it =
        std::ranges::find_if(known, [&](const TaskOption& o) { return name == o.name; });
    if (it == known.end()) {
      std::string names;
      for (const TaskOption& o : known) names += (names.empty() ? "" : ", ") + std::string(o.name);
      throw UserError("reset option '" + name + "' is not one " + std::string(env) +
                      " takes (expected " + (names.empty() ? "none" : names) + ")");
    }
    if (!(value >= it->lo && value <= it->hi)) {
      throw UserError("reset option " + name + " of " + std::string(env) + " must be in [" +
                      num(it->lo) + ", " + num(it->hi) + "], not " + num(value));
    }
    *it->value = value;
  }
}

MimoEnv::~MimoEnv() = default;

const ObservationLayout* MimoEnv::layout(std::string_view key) const {
  return key == kTouchKey && assets_->touch ? &assets_->touch_layout : nullptr;
}

void MimoEnv::reset(std::optional<std::uint64_t> seed) {
  if (seed) rng_.seed_with(*seed);
  // mj_resetData and actuation reset, the start state, then the task's goal and start.
  core_.sim().reset();
  core_.sim().restore(assets_->init);
  task_->initialize_episode(core_, rng_, goal_);
  steps_ = 0;
  info_.clear();
  task_->reset(core_, info_);
  observe();
}

void MimoEnv::observe() {
  core_.observe();
  const std::span<double> achieved = core_.achieved_goal();
  task_->observe(core_, core_.extra_proprio(), achieved);
  if (!achieved.empty()) std::ranges::copy(goal_, core_.desired_goal().begin());
}

StepResult MimoEnv::step(std::span<const double> action) {
  check_finite_actions(action);
  core_.step(task_->before_step(action, rng_), /*contact_forces=*/true);
  task_->after_physics(core_);
  observe();

  const Clock::time_point task_start = Clock::now();
  info_.steps = steps_;
  StepResult result;
  result.reward = task_->after_step(core_, info_);
  result.terminated = assets_->done_active && (success() || failure());
  ++steps_;
  const int limit = assets_->definition.max_episode_steps;
  result.truncated = limit > 0 && steps_ >= limit;
  Profile& profile = core_.profile();
  profile.other += seconds(Clock::now() - task_start);
  ++profile.steps;
  return result;
}

void MimoEnv::render(std::span<std::uint8_t> rgb) {
  const int size = assets_->options.render_size;
  const mjModel* m = core_.model();
  if (!view_) view_ = std::make_unique<senses::CameraRenderer>(m, size, size);
  view_->render(m, mutable_data(), assets_->camera, size, size, rgb);
}

HeadTracking::HeadTracking(const mjModel* m)
    : head_body_(body_id(m, "head")),
      swivel_(qpos_address(m, "robot:head_swivel")),
      tilt_(qpos_address(m, "robot:head_tilt")),
      tilt_side_(qpos_address(m, "robot:head_tilt_side")) {
  int k = 0;
  for (const char* side : {"left", "right"}) {
    for (const char* axis : {"horizontal", "vertical", "torsional"}) {
      eyes_[k++] = qpos_address(m, std::string("robot:") + side + "_eye_" + axis);
    }
  }
}

void HeadTracking::aim(const mjModel* m, mjData* d, const double target[3]) const {
  (void)m;
  // Eye height above the head's origin and the eyes' half distance (m); the eye centres sit
  // 0.07 m in front of the head's origin.
  constexpr double kEyeHeight = 0.067375, kEyeHalfDistance = 0.0245, kEyeForward = 0.07;
  const double* head = d->xpos + 3 * head_body_;
  double v[3] = {target[0] - head[0], target[1] - head[1], target[2] - head[2]};
  const double dist = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  v[2] -= kEyeHeight;
  const double eye_dist = dist - kEyeForward;
  d->qpos[swivel_] = std::atan(v[1] / v[0]);
  d->qpos[tilt_] = std::atan(-v[2] / v[0]);
  d->qpos[tilt_side_] = 0;
  // Both eyes converge on the target; no vertical or torsional eye movement.
  const double vergence = std::atan(-kEyeHalfDistance / eye_dist);
  for (int side = 0; side < 2; ++side) {
    d->qpos[eyes_[3 * side]] = vergence;
    d->qpos[eyes_[3 * side + 1]] = 0;
    d->qpos[eyes_[3 * side + 2]] = 0;
  }
}

}  // namespace cradle::envs

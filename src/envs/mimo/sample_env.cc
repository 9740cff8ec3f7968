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

// The registry, in the reference's registration order.
const std::vector<SampleDefinition>& definitions() {
  static const std::vector<SampleDefinition> all = {
      bench_definition(false), bench_definition(true), showroom_definition(), reach_definition(),
      standup_definition(),    selfbody_definition(),  catch_definition(),
  };
  return all;
}

std::string joined_names() {
  std::string names;
  for (const std::string& n : sample_env_names()) names += (names.empty() ? "" : ", ") + n;
  return names;
}

}  // namespace

const std::vector<std::string>& sample_env_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const SampleDefinition& d : definitions()) out.push_back(d.name);
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
  const auto& all = definitions();
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
  const SampleDefinition& def = assets->definition;
  std::unique_ptr<MimoEnv> env = def.make(std::move(assets), seed);
  env->reset(seed);
  return env;
}

std::unique_ptr<MimoEnv> make_sample_env(std::string_view name, const SampleOptions& options,
                                         std::uint64_t seed) {
  return make_sample_env(make_sample_assets(name, options), seed);
}

DictSpace sample_observation_space(const SampleAssets& assets, int proprio_size) {
  const SampleDefinition& def = assets.definition;
  // Keys in the reference's order: proprioception, touch, eyes, vestibular, goals.
  DictSpace space;
  space.entries.emplace_back(
      MimoEnv::kProprioKey,
      Box::unbounded({proprio_size + def.extra_observation}, DType::kFloat64));
  if (assets.touch) space.entries.emplace_back(MimoEnv::kTouchKey, assets.touch->space());
  if (def.vision) {
    const Box eye = senses::Eyes::space_for(assets.options.vision_resolution);
    space.entries.emplace_back(senses::Eyes::kLeftKey, eye);
    space.entries.emplace_back(senses::Eyes::kRightKey, eye);
  }
  if (def.vestibular) {
    space.entries.emplace_back(MimoEnv::kVestibularKey,
                               Box::unbounded({senses::Vestibular::kSize}, DType::kFloat64));
  }
  if (assets.goals_in_observation) {
    const Box goal = Box::unbounded({def.goal_size}, DType::kFloat64);
    space.entries.emplace_back(MimoEnv::kAchievedKey, goal);
    space.entries.emplace_back(MimoEnv::kDesiredKey, goal);
  }
  return space;
}

MimoEnv::MimoEnv(std::shared_ptr<const SampleAssets> assets, std::uint64_t seed)
    : assets_(std::move(assets)),
      m_(assets_->model.get()),
      sim_(m_, assets_->actuation, assets_->definition.frame_skip),
      proprio_(m_, senses::ProprioOptions{}, sim_.actuation().observation_size()),
      observation_space_(sample_observation_space(*assets_, proprio_.size())),
      obs_(observation_space_),
      proprio_index_(key_index(kProprioKey)),
      touch_index_(key_index(kTouchKey)),
      eye_left_index_(key_index(senses::Eyes::kLeftKey)),
      eye_right_index_(key_index(senses::Eyes::kRightKey)),
      vestibular_index_(key_index(kVestibularKey)),
      achieved_index_(key_index(kAchievedKey)),
      desired_index_(key_index(kDesiredKey)),
      goal_(assets_->definition.goal_size, 0.0),
      success_slot_(info_.declare("is_success", InfoType::kBool)),
      failure_slot_(info_.declare("is_failure", InfoType::kBool)),
      rng_(seed) {
  const SampleDefinition& def = assets_->definition;
  if (def.vision) eyes_ = std::make_unique<senses::Eyes>(m_, assets_->options.vision_resolution);
  if (def.vestibular) vestibular_.emplace(m_);
  sim_.restore(assets_->init);
}

MimoEnv::~MimoEnv() = default;

mjModel* MimoEnv::own_model() {
  if (!own_) {
    own_.reset(mj_copyModel(nullptr, assets_->model.get()));
    // The simulation moves onto the copy; its state carries over.
    sim::State state;
    sim_.save(state);
    sim_ = sim::Sim(own_.get(), assets_->actuation, assets_->definition.frame_skip);
    sim_.restore(state);
    m_ = own_.get();
  }
  return own_.get();
}

const ObservationLayout* MimoEnv::layout(std::string_view key) const {
  return key == kTouchKey && assets_->touch ? &assets_->touch_layout : nullptr;
}

int MimoEnv::key_index(std::string_view key) const {
  for (int i = 0; i < static_cast<int>(observation_space_.entries.size()); ++i) {
    if (observation_space_.entries[i].first == key) return i;
  }
  return -1;
}

void MimoEnv::reset(std::optional<std::uint64_t> seed) {
  if (seed) rng_.seed_with(*seed);
  // mj_resetData, actuation reset, new goal, then the task's reset from the start state.
  sim_.reset();
  sample_goal(goal_);
  restore_init();
  reset_model();
  steps_ = 0;
  info_.clear();
  observe();
}

void MimoEnv::simulate(std::span<const double> action) {
  sim::Actuation& actuation = sim_.actuation();
  mjData* data = sim_.data();
  actuation.apply(action, data);
  for (int i = 0; i < assets_->definition.frame_skip; ++i) {
    actuation.substep(data);
    mj_step(m_, data);
    mj_rnePostConstraint(m_, data);
    substep_callback();
  }
}

StepResult MimoEnv::step(std::span<const double> action) {
  check_finite_actions(action);
  const Clock::time_point start = Clock::now();
  simulate(process_action(action));
  step_callback();
  profile_.physics += seconds(Clock::now() - start);
  observe();

  const Clock::time_point task_start = Clock::now();
  info_.steps = steps_;
  info_.set(success_slot_, is_success());
  info_.set(failure_slot_, is_failure());
  StepResult result;
  result.terminated = assets_->done_active && (success() || failure());
  ++steps_;
  const int limit = assets_->definition.max_episode_steps;
  result.truncated = limit > 0 && steps_ >= limit;
  result.reward = compute_reward();
  profile_.other += seconds(Clock::now() - task_start);
  ++profile_.steps;
  return result;
}

void MimoEnv::observe() {
  mjData* data = sim_.data();
  Clock::time_point t = Clock::now();
  auto lap = [&](double& bucket) {
    const Clock::time_point now = Clock::now();
    bucket += seconds(now - t);
    t = now;
  };
  const std::span<double> vector = obs_.f64(proprio_index_);
  proprio_.read(m_, data, sim_.actuation(), vector.first(proprio_.size()));
  extra_observation(vector.subspan(proprio_.size()));
  lap(profile_.proprio);
  if (touch_index_ >= 0) {
    assets_->touch->read(m_, data, obs_.f32(touch_index_));
    lap(profile_.touch);
  }
  if (eyes_) {
    eyes_->render(m_, data, obs_.u8(eye_left_index_), obs_.u8(eye_right_index_));
    lap(profile_.vision);
  }
  if (vestibular_) {
    vestibular_->read(data, obs_.f64(vestibular_index_));
    lap(profile_.vestibular);
  }
  if (achieved_index_ >= 0) {
    achieved_goal(obs_.f64(achieved_index_));
    std::ranges::copy(goal_, obs_.f64(desired_index_).begin());
  }
}

void MimoEnv::render(std::span<std::uint8_t> rgb) {
  const int size = assets_->options.render_size;
  if (!view_) view_ = std::make_unique<senses::CameraRenderer>(m_, size, size);
  view_->render(m_, sim_.data(), assets_->camera, size, size, rgb);
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

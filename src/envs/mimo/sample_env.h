// MIMo's sample environments (mimo_core.md §5-6): reach, standup, self-body, catch, benchmark and
// showroom. MimoEnv runs the reference's MIMoEnv step loop on the one MIMo env core
// (envs/mimo_core.h, shared with BabyBench); each task is a Task (envs/task.h) in one short file
// (envs/mimo/<task>.cc: scene, start, reward, success, failure). What a task compiles to once
// (model, skin, start state) lives in SampleAssets and is shared read-only by every env built
// from it.
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/config.h"
#include "core/rng.h"
#include "envs/env.h"
#include "envs/mimo_core.h"
#include "envs/task.h"
#include "scene/compose.h"
#include "senses/touch.h"
#include "senses/vision.h"
#include "sim/sim.h"

namespace cradle::envs {

class MimoEnv;

// Constructor options of the sample envs; unset fields take the task's defaults.
struct SampleOptions {
  std::optional<ActuationModel> actuation;
  std::optional<bool> goals_in_observation;
  std::optional<bool> done_active;
  int vision_resolution = 256;  // eye images (benchmark, showroom)
  int render_size = 500;        // free-view frames (videos)
  // Catch only.
  bool action_penalty = true;        // -40 x muscle cost per step
  bool jitter = false;               // random per-dimension action gains, redrawn every 10-50 steps
  bool position_inaccurate = false;  // per-episode error of the head's aim at the ball
  // The wrist's rotation pinned at -1.4 rad as in MIMo's first catch scene, so the ball falls on
  // an open, upturned palm as the reference's documentation describes. The current reference
  // scene leaves the wrist free: at rest the palm faces sideways and the ball lands on the edge
  // of the hand unless the policy turns the palm up within the ~0.2 s fall.
  bool palm_up = false;
};

// What a task's env is: its registration, scene, senses and defaults.
struct SampleDefinition {
  std::string name;       // registered id, e.g. "MIMoReach-v0"
  int max_episode_steps;  // TimeLimit of the registration (0: none)
  int frame_skip = 2;     // physics steps per env step
  ActuationModel actuation = ActuationModel::kSpringDamper;
  bool goals_in_observation = false;
  bool done_active = true;  // terminate on success or failure
  bool vestibular = false;
  bool vision = false;
  std::map<std::string, double> touch;             // body -> sensor spacing (m); empty: no touch
  int goal_size = 0;                               // achieved/desired goal entries
  int extra_observation = 0;                       // values appended to the proprioceptive vector
  std::array<double, 3> camera_lookat{0, 0, 0.3};  // free view for videos
  double camera_distance = 1.5, camera_azimuth = 150, camera_elevation = -20;
  // The scene; the core adds the free-view camera.
  std::function<scene::Composition(const SampleOptions&)> scene;
  // The reset options a teacher can set (set_reset_options), with their ranges.
  std::vector<TaskParameter> parameters;
  // Writes the start state into d (already reset and forwarded); the core saves it as `init`.
  std::function<void(const mjModel*, mjData*)> initial_state;
  // The task of an env on its core (a task that changes the model per episode makes the core's
  // copy here). The task declares "is_success" and "is_failure" and sets them every step.
  std::function<std::unique_ptr<Task>(MimoCore& core, const SampleOptions& options)> make;
};

struct SampleAssets {
  SampleDefinition definition;
  SampleOptions options;
  ActuationModel actuation;
  bool goals_in_observation, done_active;
  scene::SceneFiles scene;
  scene::ModelPtr model;
  std::unique_ptr<senses::Touch> touch;  // null without touch
  ObservationLayout touch_layout;        // the skin's layout, published as the "touch" key's
  sim::State init;                       // the reference's init_qpos / init_qvel
  int camera = -1;                       // id of the free-view camera "view"
};

// Every sample task's definition, in the reference's registration order.
const std::vector<SampleDefinition>& sample_definitions();
// Registered names, in the reference's order.
const std::vector<std::string>& sample_env_names();
// Short names of `cradle illustrate` (reach, standup, selfbody, catch) -> registered names.
std::string sample_env_id(std::string_view short_name);
// Compiles a sample env's scene once. Throws UserError for an unknown name (listing the valid
// ones) or an option the env cannot take.
std::shared_ptr<const SampleAssets> make_sample_assets(std::string_view name,
                                                       const SampleOptions& options = {});
// An env over shared assets, reset with `seed`.
std::unique_ptr<MimoEnv> make_sample_env(std::shared_ptr<const SampleAssets> assets,
                                         std::uint64_t seed = 0);
std::unique_ptr<MimoEnv> make_sample_env(std::string_view name, const SampleOptions& options = {},
                                         std::uint64_t seed = 0);

// One reset option of a sample task: its name, accepted range and where the task keeps it (unset:
// the task draws the value as the reference does).
struct TaskOption {
  const char* name;
  double lo, hi;
  std::optional<double>* value;
};
// Keeps each option's value; UserError naming the env for an unknown name (listing the known
// ones) or a value outside its range.
void set_task_options(std::string_view env, std::span<const TaskOption> known,
                      const ResetOptions& options);

// A sample task: declares the reference's "is_success" and "is_failure" and sets them every step
// (set_outcome, from after_step); its info holds nothing else.
class SampleTask : public Task {
 public:
  void declare(Info& info) override;
  void reset(const MimoCore&, Info&) override {}

 protected:
  void set_outcome(Info& info, bool success, bool failure) const;

 private:
  int success_slot_ = -1, failure_slot_ = -1;
};

// A sample env: the reference's step order (mimo_core.md §5) on the MIMo env core, around its
// task. step(): action (task's before_step) -> frame_skip x (actuation substep, mj_step,
// mj_rnePostConstraint) -> task's after_physics -> observe -> the task's after_step (success,
// failure, reward) -> terminated = done_active && (success || failure) -> truncated at
// max_episode_steps. Randomness only from the env's own seeded generator.
class MimoEnv final : public Env {
 public:
  static constexpr const char* kProprioKey = MimoCore::kProprioKey;
  static constexpr const char* kTouchKey = MimoCore::kTouchKey;
  static constexpr const char* kVestibularKey = MimoCore::kVestibularKey;
  static constexpr const char* kAchievedKey = MimoCore::kAchievedKey;
  static constexpr const char* kDesiredKey = MimoCore::kDesiredKey;

  MimoEnv(std::shared_ptr<const SampleAssets> assets, std::uint64_t seed);
  ~MimoEnv() override;

  const DictSpace& observation_space() const override { return core_.observation_space(); }
  const Box& action_space() const override { return core_.action_space(); }
  void reset(std::optional<std::uint64_t> seed = std::nullopt) override;
  StepResult step(std::span<const double> action) override;
  const ObservationBuffers& observation() const override { return core_.observation(); }
  const Info& info() const override { return info_; }
  const ObservationLayout* layout(std::string_view key) const override;
  // The task's options (reach: target_dx/dy/dz; catch: ball_dx/dy/dz, ball_speed, ball_radius,
  // ball_mass), kept for every later reset.
  void set_reset_options(const ResetOptions& options) override {
    task_->set_reset_options(options);
  }

  const SampleAssets& assets() const { return *assets_; }
  const SampleDefinition& definition() const { return assets_->definition; }
  const mjModel* model() const { return core_.model(); }
  const mjData* data() const { return core_.data(); }
  // For tests that script states and for renderers (MuJoCo's scene update takes a non-const
  // mjData but does not change the state).
  mjData* mutable_data() const { return const_cast<mjData*>(core_.data()); }
  const senses::Touch* touch() const { return assets_->touch.get(); }
  int key_index(std::string_view key) const { return core_.key_index(key); }
  int episode_steps() const { return steps_; }
  // The task's flags of the last step (info "is_success", "is_failure").
  bool success() const { return info_.flag(success_slot_); }
  bool failure() const { return info_.flag(failure_slot_); }
  const Profile& profile() const { return core_.profile(); }
  void clear_profile() { core_.profile() = {}; }
  // Renders the free view ("view" camera) at render_size^2 into rgb (row 0 at the top).
  void render(std::span<std::uint8_t> rgb);
  int render_size() const { return assets_->options.render_size; }

 private:
  void observe();

  std::shared_ptr<const SampleAssets> assets_;
  MimoCore core_;
  std::unique_ptr<Task> task_;
  std::unique_ptr<senses::CameraRenderer> view_;
  std::vector<double> goal_;
  Info info_;
  int success_slot_ = -1, failure_slot_ = -1;
  Rng rng_;
  int steps_ = 0;
};

// Head and eyes aim at a point by setting their joint angles directly (reach and catch): the
// head turns and tilts towards it, both eyes converge on it.
class HeadTracking {
 public:
  explicit HeadTracking(const mjModel* m);
  void aim(const mjModel* m, mjData* d, const double target[3]) const;

 private:
  int head_body_;
  int swivel_, tilt_, tilt_side_;  // qpos addresses
  std::array<int, 6> eyes_;        // left h/v/t, right h/v/t
};

// Tasks (envs/mimo/<task>.cc).
SampleDefinition reach_definition();
SampleDefinition standup_definition();
SampleDefinition selfbody_definition();
// Self-body's candidate targets, in the order of its one-hot goal.
std::vector<std::string> selfbody_targets();
SampleDefinition catch_definition();
SampleDefinition bench_definition(bool v2);
SampleDefinition showroom_definition();

// Shared scene parts of the sample scenes: skybox, checker floor and a top light.
scene::WorldFragments sample_floor();
// A fixed camera named "view" looking at `lookat` like MuJoCo's free camera.
std::string look_at_camera(const std::array<double, 3>& lookat, double distance, double azimuth,
                           double elevation);
// qpos address of a joint by name; throws std::runtime_error if missing.
int qpos_address(const mjModel* m, const std::string& joint);
int body_id(const mjModel* m, const std::string& body);

}  // namespace cradle::envs

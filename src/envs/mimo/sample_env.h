// MIMo's sample environments (mimo_core.md §5-6): reach, standup, self-body, catch, benchmark and
// showroom. The shared core is MimoEnv, the reference's MIMoEnv step loop over one compiled
// scene; each task is one short file (envs/mimo/<task>.cc: scene, reset, reward, success, failure,
// callbacks). What a task compiles to once (model, skin, start state) lives in SampleAssets and
// is shared read-only by every env built from it.
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
#include "envs/babybench.h"
#include "envs/env.h"
#include "scene/compose.h"
#include "senses/proprioception.h"
#include "senses/touch.h"
#include "senses/vestibular.h"
#include "senses/vision.h"
#include "sim/sim.h"

namespace cradle::envs {

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
  // Writes the start state into d (already reset and forwarded); the core saves it as `init`.
  std::function<void(const mjModel*, mjData*)> initial_state;
  // Builds the task's env over compiled assets (the registry then resets it with the seed).
  std::function<std::unique_ptr<class MimoEnv>(std::shared_ptr<const struct SampleAssets>,
                                               std::uint64_t seed)>
      make;
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

// The base env: the reference's step order (mimo_core.md §5). step(): action -> frame_skip x
// (actuation substep, mj_step, mj_rnePostConstraint, substep callback) -> step callback ->
// observe -> success/failure -> terminated = done_active && (success || failure) -> truncated at
// max_episode_steps -> reward. Randomness only from the env's own seeded generator.
class MimoEnv : public Env {
 public:
  static constexpr const char* kProprioKey = "observation";
  static constexpr const char* kTouchKey = "touch";
  static constexpr const char* kVestibularKey = "vestibular";
  static constexpr const char* kAchievedKey = "achieved_goal";
  static constexpr const char* kDesiredKey = "desired_goal";

  MimoEnv(std::shared_ptr<const SampleAssets> assets, std::uint64_t seed);
  ~MimoEnv() override;

  const DictSpace& observation_space() const override { return observation_space_; }
  const Box& action_space() const override { return sim_.actuation().action_space(); }
  void reset(std::optional<std::uint64_t> seed = std::nullopt) override;
  StepResult step(std::span<const double> action) override;
  const ObservationBuffers& observation() const override { return obs_; }
  const Info& info() const override { return info_; }
  const ObservationLayout* layout(std::string_view key) const override;

  const SampleAssets& assets() const { return *assets_; }
  const SampleDefinition& definition() const { return assets_->definition; }
  const mjModel* model() const { return m_; }
  const mjData* data() const { return sim_.data(); }
  // For tests that script states and for renderers (MuJoCo's scene update takes a non-const
  // mjData but does not change the state).
  mjData* mutable_data() const { return const_cast<mjData*>(sim_.data()); }
  const senses::Touch* touch() const { return assets_->touch.get(); }
  int key_index(std::string_view key) const;
  int episode_steps() const { return steps_; }
  // The task's flags of the last step (info "is_success", "is_failure").
  bool success() const { return info_.flag(success_slot_); }
  bool failure() const { return info_.flag(failure_slot_); }
  const Profile& profile() const { return profile_; }
  void clear_profile() { profile_ = {}; }
  // Renders the free view ("view" camera) at render_size^2 into rgb (row 0 at the top).
  void render(std::span<std::uint8_t> rgb);
  int render_size() const { return assets_->options.render_size; }

 protected:
  // A private copy of the model for tasks that change it per episode (catch's ball size and mass,
  // gravity during settling). Call from the task's constructor.
  mjModel* own_model();
  Rng& rng() { return rng_; }
  sim::Sim& sim() { return sim_; }
  mjData* d() { return sim_.data(); }
  const std::vector<double>& goal() const { return goal_; }

  // Task hooks, named as in the reference, plus process_action (catch's jitter).
  virtual std::span<const double> process_action(std::span<const double> action) { return action; }
  virtual void sample_goal(std::span<double> goal) { (void)goal; }
  virtual void reset_model() = 0;  // after mj_resetData, actuation reset and restore(init)
  virtual void substep_callback() {}
  virtual void step_callback() {}
  virtual bool is_success() { return false; }
  virtual bool is_failure() { return false; }
  virtual double compute_reward() = 0;  // after the flags of this step (success(), failure())
  virtual void achieved_goal(std::span<double> out) { (void)out; }
  virtual void extra_observation(std::span<double> out) { (void)out; }  // extra_observation values

  // One raw physics step (no actuation substep, no callbacks), as the reference's settling.
  void raw_step() { mj_step(m_, sim_.data()); }
  // Restores the start state and recomputes derived quantities.
  void restore_init() { sim_.restore(assets_->init); }
  // Applies an action for one env step with the substep callbacks (no observation).
  void simulate(std::span<const double> action);

 private:
  void observe();

  std::shared_ptr<const SampleAssets> assets_;
  scene::ModelPtr own_;
  const mjModel* m_;
  sim::Sim sim_;
  senses::Proprioception proprio_;
  std::optional<senses::Vestibular> vestibular_;
  std::unique_ptr<senses::Eyes> eyes_;
  std::unique_ptr<senses::CameraRenderer> view_;
  DictSpace observation_space_;
  ObservationBuffers obs_;
  const int proprio_index_, touch_index_, eye_left_index_, eye_right_index_, vestibular_index_,
      achieved_index_, desired_index_;
  std::vector<double> goal_;
  Info info_;
  const int success_slot_, failure_slot_;
  Rng rng_;
  int steps_ = 0;
  Profile profile_;
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

// The observation space of a sample env whose proprioception has proprio_size values.
DictSpace sample_observation_space(const SampleAssets& assets, int proprio_size);

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

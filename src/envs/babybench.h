// The BabyBench env: the MIMo env core (simulation and senses) and a behaviour (a Task),
// configured by a BabyBench YAML config. Everything a config compiles to once (model, touch sensor
// layout, settled start state) lives in BabyBenchAssets and is shared read-only by every env built
// from it.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/config.h"
#include "core/rng.h"
#include "envs/env.h"
#include "envs/mimo_core.h"
#include "envs/self_touch.h"
#include "envs/task.h"
#include "envs/training_log.h"
#include "scene/compose.h"
#include "senses/touch.h"
#include "sim/sim.h"

namespace cradle::envs {

// Builds an env the way babybench.utils.make_env does. training = true creates <save_dir> with
// logs/ and videos/, writes scene/scene.xml (and its textures) there and attaches a new training
// log.
std::unique_ptr<class BabyBenchEnv> make_env(const Config& config, bool training,
                                             std::uint64_t seed = 0);

struct BabyBenchAssets {
  Config config;
  scene::SceneFiles scene;  // what compiled `model`; written as scene/scene.xml in training mode
  scene::ModelPtr model;
  std::unique_ptr<senses::Touch> touch;  // null when touch is off
  ObservationLayout touch_layout;        // the skin's layout, published as the "touch" key's
  sim::State settled;  // after 100 zero-action physics steps: every episode starts here
};

// Compiles the config's scene, lays out the skin and settles the pose. Throws UserError for
// configs that cannot run.
std::shared_ptr<const BabyBenchAssets> make_assets(const Config& config);
// The same from a scene.xml written by a training run (evaluation reuses the training scene).
std::shared_ptr<const BabyBenchAssets> make_assets(const Config& config,
                                                   const std::filesystem::path& scene_file);

// Prepares <save_dir> for a training run (scene/, logs/, videos/) and opens a new training log
// there, for one env or for every env of a vector. continue_log >= 0: continues the log, which
// holds that many entries (a resumed run).
std::shared_ptr<TrainingLog> start_training(const BabyBenchAssets& assets, long continue_log = -1);

// The reset options a teacher can set on a config's env (set_reset_options), with their ranges:
// start_posture_range, randomize_start, and cube_distance in the cubes scene.
std::vector<TaskParameter> babybench_task_parameters(const Config& config);

// The observation space a config produces, without building an env (no GL context needed).
DictSpace babybench_observation_space(const BabyBenchAssets& assets, int actuation_obs_size);

class BabyBenchEnv final : public Env {
 public:
  // Observation keys, in the reference's order.
  static constexpr const char* kProprioKey = MimoCore::kProprioKey;
  static constexpr const char* kTouchKey = MimoCore::kTouchKey;
  static constexpr const char* kEyeLeftKey = senses::Eyes::kLeftKey;
  static constexpr const char* kEyeRightKey = senses::Eyes::kRightKey;
  static constexpr const char* kVestibularKey = MimoCore::kVestibularKey;
  // Info key: MuJoCo size overflows (contacts, constraints, stack) in this episode; the step that
  // overflows ends the episode (truncated). 0 in every normal episode.
  static constexpr const char* kOverflowKey = "physics_overflow";
  // Info key: 1 when the physics diverged in this episode (NaN or huge values; MuJoCo reset the
  // data mid-step); that step ends the episode (truncated). 0 in every normal episode.
  static constexpr const char* kDivergedKey = "physics_diverged";

  static constexpr int kSettleSteps = 100;      // zero-action physics steps at construction
  static constexpr int kRandomResetSteps = 10;  // random actions applied at every reset

  explicit BabyBenchEnv(std::shared_ptr<const BabyBenchAssets> assets, std::uint64_t seed = 0);
  ~BabyBenchEnv() override;

  // Training mode: every reset records the episode that just ended (the first reset records a
  // 0-step entry, as the reference does); close() records the last, partial one.
  // `slot` (the env's index in a vector) orders its entries in the log (TrainingLog::set_slots).
  void attach_log(std::shared_ptr<TrainingLog> log, int slot = -1) {
    log_ = std::move(log);
    log_slot_ = slot;
  }
  const std::shared_ptr<TrainingLog>& log() const { return log_; }
  // Records the current episode now (e.g. cut short at a checkpoint); the next reset or close
  // then records nothing for it.
  void end_episode();
  // The next reset records nothing (a resumed run: the episode before it was never this env's).
  void skip_next_record() { skip_record_ = true; }
  // Random start postures: every reset draws each free MIMo joint (not held by an active joint
  // equality) uniformly within its range before the random start actions (reset option
  // "randomize_start" = 1).
  void set_randomize_start(bool on) { randomize_start_ = on; }
  void set_reset_options(const ResetOptions& options) override;
  void close() override;
  double score() const override { return task_->score(info_, steps_); }
  const ObservationLayout* layout(std::string_view key) const override;

  const DictSpace& observation_space() const override { return core_.observation_space(); }
  const Box& action_space() const override { return core_.action_space(); }
  void reset(std::optional<std::uint64_t> seed = std::nullopt) override;
  StepResult step(std::span<const double> action) override;
  const ObservationBuffers& observation() const override { return core_.observation(); }
  const Info& info() const override { return info_; }

  const Config& config() const { return assets_->config; }
  const mjModel* model() const { return assets_->model.get(); }
  const mjData* data() const { return core_.data(); }
  // For renderers only: MuJoCo's scene update takes a non-const mjData but does not change the
  // simulation state.
  mjData* render_data() const { return const_cast<mjData*>(core_.data()); }
  const Task& task() const { return *task_; }
  const senses::Touch* touch() const { return assets_->touch.get(); }
  const senses::Proprioception& proprioception() const { return core_.proprioception(); }
  int episode_steps() const { return steps_; }
  const Profile& profile() const { return core_.profile(); }
  void clear_profile() { core_.profile() = {}; }
  // Index of an observation key in observation_space() (-1 if absent).
  int key_index(std::string_view key) const { return core_.key_index(key); }

 private:
  std::shared_ptr<const BabyBenchAssets> assets_;
  MimoCore core_;
  std::unique_ptr<Task> task_;
  HandContacts contacts_;
  std::shared_ptr<TrainingLog> log_;
  int log_slot_ = -1;
  bool skip_record_ = false;  // the current episode is already recorded (or not this env's)
  int overflow_slot_ = -1;    // info "physics_overflow": MuJoCo size overflows this episode
  int diverged_slot_ = -1;    // info "physics_diverged": the physics diverged this episode
  Info info_;
  Rng rng_;
  std::vector<double> random_action_;
  bool randomize_start_ = false;
  double start_posture_range_ = 0;  // [0, 1]: share of each joint's range drawn around the start
  // Reset option cube_distance (cubes scene): the stacked cubes' horizontal distance from MIMo's
  // root (m); <= 0: where the scene puts them.
  double cube_distance_ = 0;
  int root_joint_ = -1;           // MIMo's free joint (mimo_location)
  std::vector<int> cube_qpos_;    // red, yellow and blue cube's free-joint qpos addresses
  std::vector<int> free_joints_;  // robot:* joints no active joint equality holds
  int steps_ = 0;
};

}  // namespace cradle::envs

// The SaMI environment family, Gymnasium-shaped (EnvPool style): a small spec plus
// reset(seed) / step(action). Hidden task parameters (mass, damping, crippled joints, table
// friction, cube mass) are redrawn at every reset from the env's task sets and written into the
// env's private copy of the few model arrays they change; the shared compiled model is read-only.
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "core/rng.h"
#include "core/spaces.h"
#include "sami/models.h"
#include "sami/task.h"

namespace cradle::sami {

// Panda skill labels (tma_sami.md §7.2), per step and per episode.
enum class Skill { kNone, kPush, kRoll, kPickAndPlace, kDown };
std::string_view skill_name(Skill skill);  // "none", "push", "roll", "pick_and_place", "down"

// One key of the observation: a slice of the flat observation vector.
struct ObsKey {
  std::string name;
  int offset = 0, size = 0;
};

struct Spec {
  EnvId id{};
  std::string name;
  std::vector<ObsKey> keys;  // "observation" (+ "achieved_goal", "desired_goal" for Panda)
  int obs_size = 0;
  // float32 as in the reference's gym envs (computed in double, rounded when written).
  DType obs_dtype = DType::kFloat32;
  int action_size = 0;
  double action_low = -1, action_high = 1;  // the same bounds on every action entry
  int horizon = 0;                          // truncation after this many steps
  int frame_skip = 0;                       // mj_steps per env step
  double dt = 0;                            // seconds per env step
  Robot robot{};

  DictSpace observation_space() const;
  Box action_space() const;
};

// The hidden parameters of the current episode and the step's extras. For analysis only: none of
// it enters the observation.
struct Info {
  int steps = 0;               // env steps done in this episode
  int task_set = 0;            // index of the task set the parameters were drawn from
  double mass = 1;             // mass factor (Panda: cube mass in kg)
  double damping = 1;          // damping factor
  double friction = 0;         // Panda: table lateral friction as configured (0 elsewhere)
  std::vector<int> crippled;   // crippled joints (Ant: legs), ascending
  bool masked = false;         // whether the crippled actuators are masked (else geometry only)
  double x_velocity = 0;       // locomotion: forward velocity of the last step
  Skill skill = Skill::kNone;  // Panda: this step's label
  Skill episode_skill = Skill::kNone;  // Panda: the episode's label so far
  bool is_success = false;             // Panda: cube within 5 cm of the goal
};

struct StepResult {
  double reward = 0;
  bool terminated = false;
  bool truncated = false;
};

// Options that depart from the published runs on purpose.
struct Options {
  // Fill cfrc_ext (mj_rnePostConstraint) so the Ant contact cost and the HumanoidStandup impact
  // cost act as written; off by default, as in the published runs (mujoco-py left them zero).
  bool contact_forces = false;
};

class SamiEnv {
 public:
  virtual ~SamiEnv() = default;
  SamiEnv(const SamiEnv&) = delete;
  SamiEnv& operator=(const SamiEnv&) = delete;

  const Spec& spec() const { return spec_; }
  // Starts an episode; a seed reseeds the env's generator, no seed continues its stream.
  void reset(std::optional<std::uint64_t> seed = std::nullopt) {
    reset_episode(seed);
    publish_observation();
  }
  // One env step; throws UserError for an action of the wrong size.
  StepResult step(std::span<const double> action) {
    const StepResult r = step_episode(action);
    publish_observation();
    return r;
  }
  // The observation in float32, the reference's dtype: the double computation rounded.
  std::span<const float> observation() const { return obs32_; }
  std::span<const float> observation(const ObsKey& key) const {
    return std::span<const float>(obs32_).subspan(key.offset, key.size);
  }
  // The observation as computed, in double, before the rounding (for tests and analysis).
  std::span<const double> observation_f64() const { return obs_; }
  // One factor per action entry that the crippling multiplies the action with (0: a masked
  // actuator); empty when the env masks nothing.
  virtual std::span<const double> action_mask() const { return {}; }
  const Info& info() const { return info_; }
  const std::vector<TaskSet>& task_sets() const { return sets_; }
  // The task sets of the following resets (a teacher's choice); UserError for invalid ones.
  void set_task_sets(std::vector<TaskSet> sets) {
    validate(spec_.id, sets);
    sets_ = std::move(sets);
  }

  // The env's model: the shared one with this env's hidden parameters (read it, never write it).
  const mjModel* model() const { return &model_; }
  const mjModel* shared_model() const { return shared_.get(); }
  mjData* data() { return data_.get(); }
  const mjData* data() const { return data_.get(); }

 protected:
  SamiEnv(Spec spec, ModelPtr shared, std::vector<TaskSet> sets, std::uint64_t seed);
  // The family's episode start and step: they compute the observation into obs_ (double);
  // reset() and step() round it to float32 afterwards.
  virtual void reset_episode(std::optional<std::uint64_t> seed) = 0;
  virtual StepResult step_episode(std::span<const double> action) = 0;
  void check_action(std::span<const double> action) const;
  // Draws the task set for the episode (uniformly) and restores the private arrays.
  const TaskSet& begin_reset(std::optional<std::uint64_t> seed);
  double pick(const std::vector<double>& values) { return values[rng_.next() % values.size()]; }
  double normal();  // standard normal (Box-Muller)

  Spec spec_;
  ModelPtr shared_;
  mjModel model_;  // a header copy of *shared_ whose parameter arrays point at the vectors below
  std::unique_ptr<mjData, void (*)(mjData*)> data_;
  std::vector<mjtNum> body_mass_, body_inertia_, dof_damping_, geom_size_, geom_friction_,
      pair_friction_;
  std::vector<float> geom_rgba_;
  std::vector<TaskSet> sets_;
  std::vector<double> obs_;  // written by reset_episode / step_episode
  Info info_;
  Rng rng_;

 private:
  void publish_observation() {
    for (size_t i = 0; i < obs_.size(); ++i) obs32_[i] = static_cast<float>(obs_[i]);
  }
  std::vector<float> obs32_;
};

// The spec of a named env (no model compiled).
Spec env_spec(EnvId id);
// A new env. `model` may be a model already compiled for spec.robot (shared by a vector); null
// compiles one. Throws UserError for empty or invalid task sets.
std::unique_ptr<SamiEnv> make_env(EnvId id, std::vector<TaskSet> sets, std::uint64_t seed,
                                  ModelPtr model = nullptr, Options options = {});
// Convenience: the env's built-in split, all its task sets in one env.
std::unique_ptr<SamiEnv> make_env(std::string_view name, std::string_view split, std::uint64_t seed,
                                  Options options = {});

}  // namespace cradle::sami

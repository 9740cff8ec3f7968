// The one MIMo env core: MIMo's simulation (Sim over a compiled scene) and his senses
// (proprioception, touch, eyes, vestibular) writing one observation dict, in the reference's key
// order. BabyBench and the MIMo sample envs build on it and add their task (envs/task.h); the
// core knows no task.
#pragma once

#include <mujoco/mujoco.h>

#include <memory>
#include <optional>
#include <span>
#include <string_view>

#include "core/config.h"
#include "envs/env.h"
#include "scene/compose.h"
#include "senses/proprioception.h"
#include "senses/touch.h"
#include "senses/vestibular.h"
#include "senses/vision.h"
#include "sim/sim.h"

namespace cradle::envs {

// The senses an env observes. Keys, in this order: "observation" (proprioception, then
// `extra_proprio` values the task appends), "touch", "eye_left" / "eye_right", "vestibular",
// "achieved_goal" / "desired_goal".
struct MimoSenses {
  senses::ProprioOptions proprio;
  int extra_proprio = 0;
  const senses::Touch* touch = nullptr;  // null: no touch key
  int vision_resolution = 0;             // eye images; 0: no eyes
  bool vestibular = false;
  bool goals = false;  // achieved/desired goal keys of goal_size values (maybe 0)
  int goal_size = 0;
};

// Wall time per env step spent in each module (for `cradle bench`).
struct Profile {
  double physics = 0, touch = 0, vision = 0, proprio = 0, vestibular = 0, other = 0;  // seconds
  long steps = 0;
};

// The skin's layout: 1 or 3 values per sensor; groupings "geom" and "body" (the geom and body
// each sensor sits on; a body's sensors are contiguous).
ObservationLayout skin_layout(const senses::Touch& touch);

// The observation space of MIMo with these senses (no GL context needed).
DictSpace mimo_observation_space(const mjModel* m, const MimoSenses& senses,
                                 int actuation_obs_size);

class MimoCore {
 public:
  static constexpr const char* kProprioKey = "observation";
  static constexpr const char* kTouchKey = "touch";
  static constexpr const char* kVestibularKey = "vestibular";
  static constexpr const char* kAchievedKey = "achieved_goal";
  static constexpr const char* kDesiredKey = "desired_goal";

  MimoCore(const mjModel* m, ActuationModel actuation, int frame_skip, const MimoSenses& senses);

  const mjModel* model() const { return m_; }
  mjData* data() { return sim_.data(); }
  const mjData* data() const { return sim_.data(); }
  sim::Sim& sim() { return sim_; }
  const sim::Sim& sim() const { return sim_; }
  const Box& action_space() const { return sim_.actuation().action_space(); }
  const senses::Touch* touch() const { return senses_.touch; }
  const senses::Proprioception& proprioception() const { return proprio_; }

  const DictSpace& observation_space() const { return space_; }
  const ObservationBuffers& observation() const { return obs_; }
  // Index of an observation key (-1 if absent).
  int key_index(std::string_view key) const;
  // The task's parts of the observation: values appended to proprioception, the goals.
  std::span<double> extra_proprio();
  std::span<double> achieved_goal();
  std::span<double> desired_goal();

  // A private copy of the model for tasks that change it per episode (catch's ball, gravity
  // while settling); the simulation moves onto it with its state.
  mjModel* own_model();

  // One env step: the action once, then frame_skip x (actuation substep, mj_step); with
  // `contact_forces` also mj_rnePostConstraint after each substep (the sample envs' order).
  void step(std::span<const double> action, bool contact_forces);
  // One raw physics step (no actuation substep), as the reference's settling.
  void raw_step() { mj_step(m_, sim_.data()); }
  // Reads every sense into the observation.
  void observe();

  Profile& profile() { return profile_; }
  const Profile& profile() const { return profile_; }

 private:
  scene::ModelPtr own_;
  const mjModel* m_;
  ActuationModel actuation_;
  MimoSenses senses_;
  sim::Sim sim_;
  senses::Proprioception proprio_;
  std::optional<senses::Vestibular> vestibular_;
  std::unique_ptr<senses::Eyes> eyes_;
  DictSpace space_;
  ObservationBuffers obs_;
  const int proprio_index_, touch_index_, eye_left_index_, eye_right_index_, vestibular_index_,
      achieved_index_, desired_index_;
  Profile profile_;
};

}  // namespace cradle::envs

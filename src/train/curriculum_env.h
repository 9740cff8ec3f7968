// An env whose tasks a teacher chooses: wraps any envs::Env that takes its task parameters as
// reset options (Env::set_reset_options), asks the TeacherController for a task before every
// reset, forwards every step to it (SPDL's step_update) and reports every finished episode
// (return, length, success). Learners see only the Env interface and stay unchanged.
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "envs/env.h"
#include "learn/learner.h"
#include "teach/controller.h"

namespace cradle::train {

struct CurriculumOptions {
  // An episode is a success when its return exceeds this (TeachMyAgent: 230); NaN: when the
  // env's info flag "is_success" is set at its last step.
  double success_threshold = std::numeric_limits<double>::quiet_NaN();
  // Forward every step to the controller (its step count and SPDL's step_update).
  bool step_updates = true;
  // The teacher hears the env's score() of the episode (e.g. BabyBench's behaviour score)
  // instead of its return.
  bool use_score = false;
};

class CurriculumEnv : public envs::Env {
 public:
  CurriculumEnv(std::unique_ptr<envs::Env> inner,
                std::shared_ptr<teach::TeacherController> controller,
                CurriculumOptions options = {});

  const DictSpace& observation_space() const override { return inner_->observation_space(); }
  const Box& action_space() const override { return inner_->action_space(); }
  void reset(std::optional<std::uint64_t> seed = std::nullopt) override;
  envs::StepResult step(std::span<const double> action) override;
  const envs::ObservationBuffers& observation() const override { return inner_->observation(); }
  const envs::Info& info() const override { return inner_->info(); }
  // Options the teacher does not set (e.g. randomize_start) go to the wrapped env; a teacher's
  // parameter is refused (UserError).
  void set_reset_options(const envs::ResetOptions& options) override;
  void close() override { inner_->close(); }
  double score() const override { return inner_->score(); }
  const envs::ObservationLayout* layout(std::string_view key) const override {
    return inner_->layout(key);
  }

  envs::Env& inner() { return *inner_; }
  // The task of the current episode (real space) and the teacher's vector for it.
  const teach::SampledTask& task() const { return task_; }
  // Seconds spent in the controller (the teacher's share of a run).
  double teacher_seconds() const { return teacher_seconds_; }

 private:
  void flatten(std::vector<float>& out) const;  // every non-image observation key, as floats

  std::unique_ptr<envs::Env> inner_;
  std::shared_ptr<teach::TeacherController> controller_;
  CurriculumOptions options_;
  envs::ResetOptions reset_options_, extra_options_;
  teach::SampledTask task_;
  std::vector<float> s_, s_next_, a_;
  double return_ = 0, teacher_seconds_ = 0;
  int length_ = 0, success_slot_ = -1;
  bool in_episode_ = false;
};

// SPDL's value estimator (Teacher::set_value_estimator) over a student's Learner::value: each
// state in CurriculumEnv's flat layout (the non-image keys of `space` in order; image keys stay
// zero) goes back into observation buffers and is valued. `learner` is asked at every call, so
// a replaced student (criterion 3) is the one valued. UserError for a state of the wrong size or
// a learner without a value function.
teach::ValueEstimator learner_value_estimator(std::function<learn::Learner&()> learner,
                                              const DictSpace& space);

}  // namespace cradle::train

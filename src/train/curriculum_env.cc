#include "train/curriculum_env.h"

#include <chrono>
#include <cmath>
#include <string>

#include "core/error.h"

namespace cradle::train {
namespace {

using Clock = std::chrono::steady_clock;

double since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

CurriculumEnv::CurriculumEnv(std::unique_ptr<envs::Env> inner,
                             std::shared_ptr<teach::TeacherController> controller,
                             CurriculumOptions options)
    : inner_(std::move(inner)), controller_(std::move(controller)), options_(options) {
  if (!inner_ || !controller_) throw std::invalid_argument("CurriculumEnv: null env or controller");
  success_slot_ = inner_->info().find("is_success");
  // Vectors sized once: a step allocates nothing.
  flatten(s_);
  s_next_ = s_;
  a_.assign(inner_->action_space().size(), 0.f);
}

void CurriculumEnv::set_reset_options(const envs::ResetOptions& options) {
  for (const auto& [name, value] : options) {
    for (const std::string& dim : controller_->space().dim_names()) {
      if (dim == name) {
        throw UserError("reset option '" + name + "' is a teacher's task parameter here");
      }
    }
  }
  extra_options_ = options;
}

void CurriculumEnv::reset(std::optional<std::uint64_t> seed) {
  // The teacher picks the next task; the env takes it as reset options.
  Clock::time_point start = Clock::now();
  task_ = controller_->sample_train_task();
  teacher_seconds_ += since(start);
  reset_options_ = extra_options_;
  const std::vector<std::string>& names = controller_->space().dim_names();
  for (std::size_t i = 0; i < names.size(); ++i) reset_options_[names[i]] = task_.real[i];
  inner_->set_reset_options(reset_options_);
  inner_->reset(seed);
  flatten(s_);
  start = Clock::now();
  controller_->record_initial_state(task_.raw, s_);
  teacher_seconds_ += since(start);
  return_ = 0;
  length_ = 0;
  in_episode_ = true;
}

envs::StepResult CurriculumEnv::step(std::span<const double> action) {
  const envs::StepResult r = inner_->step(action);
  const bool done = r.terminated || r.truncated;
  return_ += r.reward;
  ++length_;
  const Clock::time_point start = Clock::now();
  // Every step to the controller (its count, SPDL's updates).
  if (options_.step_updates) {
    for (std::size_t i = 0; i < a_.size() && i < action.size(); ++i)
      a_[i] = static_cast<float>(action[i]);
    flatten(s_next_);
    controller_->record_train_step(s_, a_, r.reward, s_next_, done);
    std::swap(s_, s_next_);
  }
  // The episode's outcome to the teacher.
  if (done && in_episode_) {
    const bool success =
        std::isnan(options_.success_threshold)
            ? success_slot_ >= 0 && inner_->info().flag(success_slot_)
            : (options_.use_score ? inner_->score() : return_) > options_.success_threshold;
    const double outcome = options_.use_score ? inner_->score() : return_;
    controller_->record_train_episode(task_.raw, std::isnan(outcome) ? 0.0 : outcome, length_,
                                      success);
    in_episode_ = false;
  }
  teacher_seconds_ += since(start);
  return r;
}

void CurriculumEnv::flatten(std::vector<float>& out) const {
  const envs::ObservationBuffers& obs = inner_->observation();
  const DictSpace& space = inner_->observation_space();
  std::size_t n = 0;
  for (int k = 0; k < obs.count(); ++k) {
    const DType t = space.entries[k].second.dtype;
    if (t == DType::kUInt8) continue;
    const std::size_t size = t == DType::kFloat64 ? obs.f64(k).size() : obs.f32(k).size();
    if (out.size() < n + size) out.resize(n + size);
    if (t == DType::kFloat64) {
      for (double v : obs.f64(k)) out[n++] = static_cast<float>(v);
    } else {
      for (float v : obs.f32(k)) out[n++] = v;
    }
  }
  out.resize(n);
}

teach::ValueEstimator learner_value_estimator(std::function<learn::Learner&()> learner,
                                              const DictSpace& space) {
  return [learner = std::move(learner), space](const std::vector<std::vector<float>>& states) {
    envs::ObservationBuffers obs(space);
    // The flat size: every non-image key.
    std::size_t total = 0;
    for (int k = 0; k < obs.count(); ++k) {
      const DType t = space.entries[k].second.dtype;
      if (t != DType::kUInt8) total += t == DType::kFloat64 ? obs.f64(k).size() : obs.f32(k).size();
    }
    std::vector<float> values;
    values.reserve(states.size());
    for (const std::vector<float>& state : states) {
      if (state.size() != total) {
        throw UserError("value estimator: a state of " + std::to_string(state.size()) +
                        " values, expected the env's " + std::to_string(total) +
                        " non-image observation values");
      }
      // The flat state back into the buffers, key by key as flatten() wrote it.
      std::size_t n = 0;
      for (int k = 0; k < obs.count(); ++k) {
        const DType t = space.entries[k].second.dtype;
        if (t == DType::kFloat64) {
          for (double& v : obs.f64(k)) v = state[n++];
        } else if (t != DType::kUInt8) {
          for (float& v : obs.f32(k)) v = state[n++];
        }
      }
      const double v = learner().value(obs);
      if (std::isnan(v)) {
        throw UserError("Self-Paced needs a student with a value function (ppo or sac), not " +
                        std::string(learner().algorithm()));
      }
      values.push_back(static_cast<float>(v));
    }
    return values;
  };
}

}  // namespace cradle::train

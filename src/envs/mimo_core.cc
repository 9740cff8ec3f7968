#include "envs/mimo_core.h"

#include <algorithm>
#include <chrono>

namespace cradle::envs {
namespace {

using Clock = std::chrono::steady_clock;

double seconds(Clock::duration d) { return std::chrono::duration<double>(d).count(); }

}  // namespace

ObservationLayout skin_layout(const senses::Touch& touch) {
  ObservationLayout layout{.values_per_item = touch.values_per_sensor()};
  const std::span<const int> geoms = touch.sensor_geoms(), bodies = touch.sensor_bodies();
  layout.groups["geom"].assign(geoms.begin(), geoms.end());
  layout.groups["body"].assign(bodies.begin(), bodies.end());
  return layout;
}

DictSpace mimo_observation_space(const mjModel* m, const MimoSenses& senses,
                                 int actuation_obs_size) {
  // Keys in the reference's order: proprioception, touch, eyes, vestibular, goals.
  DictSpace space;
  const int proprio = senses::Proprioception(m, senses.proprio, actuation_obs_size).size();
  space.entries.emplace_back(MimoCore::kProprioKey,
                             Box::unbounded({proprio + senses.extra_proprio}, DType::kFloat64));
  if (senses.touch) space.entries.emplace_back(MimoCore::kTouchKey, senses.touch->space());
  if (senses.vision_resolution > 0) {
    const Box eye = senses::Eyes::space_for(senses.vision_resolution);
    space.entries.emplace_back(senses::Eyes::kLeftKey, eye);
    space.entries.emplace_back(senses::Eyes::kRightKey, eye);
  }
  if (senses.vestibular) {
    space.entries.emplace_back(MimoCore::kVestibularKey,
                               Box::unbounded({senses::Vestibular::kSize}, DType::kFloat64));
  }
  if (senses.goals) {
    const Box goal = Box::unbounded({senses.goal_size}, DType::kFloat64);
    space.entries.emplace_back(MimoCore::kAchievedKey, goal);
    space.entries.emplace_back(MimoCore::kDesiredKey, goal);
  }
  return space;
}

MimoCore::MimoCore(const mjModel* m, ActuationModel actuation, int frame_skip,
                   const MimoSenses& senses)
    : m_(m),
      actuation_(actuation),
      senses_(senses),
      sim_(m, actuation, frame_skip),
      proprio_(m, senses.proprio, sim_.actuation().observation_size()),
      space_(mimo_observation_space(m, senses, sim_.actuation().observation_size())),
      obs_(space_),
      proprio_index_(key_index(kProprioKey)),
      touch_index_(key_index(kTouchKey)),
      eye_left_index_(key_index(senses::Eyes::kLeftKey)),
      eye_right_index_(key_index(senses::Eyes::kRightKey)),
      vestibular_index_(key_index(kVestibularKey)),
      achieved_index_(key_index(kAchievedKey)),
      desired_index_(key_index(kDesiredKey)) {
  if (senses.vestibular) vestibular_.emplace(m);
  if (senses.vision_resolution > 0) {
    eyes_ = std::make_unique<senses::Eyes>(m, senses.vision_resolution);
  }
}

int MimoCore::key_index(std::string_view key) const {
  for (int i = 0; i < static_cast<int>(space_.entries.size()); ++i) {
    if (space_.entries[i].first == key) return i;
  }
  return -1;
}

std::span<double> MimoCore::extra_proprio() {
  return obs_.f64(proprio_index_).subspan(proprio_.size());
}

std::span<double> MimoCore::achieved_goal() {
  return achieved_index_ >= 0 ? obs_.f64(achieved_index_) : std::span<double>();
}

std::span<double> MimoCore::desired_goal() {
  return desired_index_ >= 0 ? obs_.f64(desired_index_) : std::span<double>();
}

mjModel* MimoCore::own_model() {
  if (!own_) {
    own_.reset(mj_copyModel(nullptr, m_));
    // The simulation moves onto the copy; its state carries over.
    sim::State state;
    sim_.save(state);
    sim_ = sim::Sim(own_.get(), actuation_, sim_.frame_skip());
    sim_.restore(state);
    m_ = own_.get();
  }
  return own_.get();
}

void MimoCore::step(std::span<const double> action, bool contact_forces) {
  const Clock::time_point start = Clock::now();
  if (!contact_forces) {
    sim_.step(action);
  } else {
    sim::Actuation& actuation = sim_.actuation();
    mjData* d = sim_.data();
    actuation.apply(action, d);
    for (int i = 0; i < sim_.frame_skip(); ++i) {
      actuation.substep(d);
      mj_step(m_, d);
      mj_rnePostConstraint(m_, d);
    }
  }
  profile_.physics += seconds(Clock::now() - start);
}

void MimoCore::observe() {
  mjData* d = sim_.data();
  Clock::time_point t = Clock::now();
  auto lap = [&](double& bucket) {
    const Clock::time_point now = Clock::now();
    bucket += seconds(now - t);
    t = now;
  };
  proprio_.read(m_, d, sim_.actuation(), obs_.f64(proprio_index_).first(proprio_.size()));
  lap(profile_.proprio);
  if (touch_index_ >= 0) {
    senses_.touch->read(m_, d, obs_.f32(touch_index_));
    lap(profile_.touch);
  }
  if (eyes_) {
    eyes_->render(m_, d, obs_.u8(eye_left_index_), obs_.u8(eye_right_index_));
    lap(profile_.vision);
  }
  if (vestibular_) {
    vestibular_->read(d, obs_.f64(vestibular_index_));
    lap(profile_.vestibular);
  }
}

}  // namespace cradle::envs

#include "sami/env.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "sami/envs/env_def.h"
#include "sami/locomotion.h"

namespace cradle::sami {

std::string_view skill_name(Skill skill) {
  switch (skill) {
    case Skill::kNone:
      return "none";
    case Skill::kPush:
      return "push";
    case Skill::kRoll:
      return "roll";
    case Skill::kPickAndPlace:
      return "pick_and_place";
    case Skill::kDown:
      return "down";
  }
  return "?";
}

DictSpace Spec::observation_space() const {
  DictSpace space;
  for (const ObsKey& key : keys)
    space.entries.push_back({key.name, Box::unbounded({key.size}, obs_dtype)});
  return space;
}

Box Spec::action_space() const {
  return Box::uniform({action_size}, DType::kFloat32, action_low, action_high);
}

Spec env_spec(EnvId id) {
  const EnvDef& def = env_def(id);
  Spec s;
  s.id = id;
  s.name = std::string(def.name);
  s.keys = def.keys.empty() ? std::vector<ObsKey>{{"observation", 0, def.obs_size}} : def.keys;
  s.obs_size = def.obs_size;
  s.action_size = def.action_size;
  s.action_low = def.action_low, s.action_high = def.action_high;
  s.horizon = def.horizon;
  s.frame_skip = def.frame_skip;
  s.dt = def.dt;
  s.robot = def.robot;
  return s;
}

SamiEnv::SamiEnv(Spec spec, ModelPtr shared, std::vector<TaskSet> sets, std::uint64_t seed)
    : spec_(std::move(spec)),
      shared_(std::move(shared)),
      model_(*shared_),
      data_(mj_makeData(shared_.get()), mj_deleteData),
      sets_(std::move(sets)),
      obs_(spec_.obs_size, 0.0),
      rng_(seed),
      obs32_(spec_.obs_size, 0.0f) {
  // The private parameter arrays start as copies of the shared model's.
  const mjModel* m = shared_.get();
  body_mass_.assign(m->body_mass, m->body_mass + m->nbody);
  body_inertia_.assign(m->body_inertia, m->body_inertia + 3 * m->nbody);
  dof_damping_.assign(m->dof_damping, m->dof_damping + m->nv);
  geom_size_.assign(m->geom_size, m->geom_size + 3 * m->ngeom);
  geom_friction_.assign(m->geom_friction, m->geom_friction + 3 * m->ngeom);
  pair_friction_.assign(m->pair_friction, m->pair_friction + 5 * m->npair);
  geom_rgba_.assign(m->geom_rgba, m->geom_rgba + 4 * m->ngeom);
  model_.body_mass = body_mass_.data();
  model_.body_inertia = body_inertia_.data();
  model_.dof_damping = dof_damping_.data();
  model_.geom_size = geom_size_.data();
  model_.geom_friction = geom_friction_.data();
  model_.pair_friction = pair_friction_.data();
  model_.geom_rgba = geom_rgba_.data();
  info_.crippled.reserve(8);
}

void SamiEnv::check_action(std::span<const double> action) const {
  if (static_cast<int>(action.size()) != spec_.action_size) {
    throw UserError(spec_.name + ": action has " + std::to_string(action.size()) +
                    " entries; expected " + std::to_string(spec_.action_size));
  }
}

const TaskSet& SamiEnv::begin_reset(std::optional<std::uint64_t> seed) {
  if (seed) rng_.seed_with(*seed);
  const mjModel* m = shared_.get();
  std::copy_n(m->body_mass, body_mass_.size(), body_mass_.begin());
  std::copy_n(m->body_inertia, body_inertia_.size(), body_inertia_.begin());
  std::copy_n(m->dof_damping, dof_damping_.size(), dof_damping_.begin());
  std::copy_n(m->geom_size, geom_size_.size(), geom_size_.begin());
  std::copy_n(m->geom_friction, geom_friction_.size(), geom_friction_.begin());
  std::copy_n(m->pair_friction, pair_friction_.size(), pair_friction_.begin());
  std::copy_n(m->geom_rgba, geom_rgba_.size(), geom_rgba_.begin());
  mj_resetData(&model_, data_.get());
  info_.task_set = static_cast<int>(rng_.next() % sets_.size());
  info_.steps = 0;
  info_.crippled.clear();
  info_.masked = false;
  info_.mass = info_.damping = 1;
  info_.friction = 0;
  info_.x_velocity = 0;
  info_.skill = info_.episode_skill = Skill::kNone;
  info_.is_success = false;
  return sets_[info_.task_set];
}

double SamiEnv::normal() {
  // Box-Muller on (0, 1] x [0, 1).
  const double u = 1.0 - rng_.uniform(), v = rng_.uniform();
  return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * M_PI * v);
}

std::unique_ptr<SamiEnv> make_env(EnvId id, std::vector<TaskSet> sets, std::uint64_t seed,
                                  ModelPtr model, Options options) {
  validate(id, sets);
  Spec spec = env_spec(id);
  if (!model) model = compile_robot(spec.robot);
  const EnvDef& def = env_def(id);
  if (def.make) return def.make(std::move(spec), model, std::move(sets), seed, options);
  return make_locomotion(std::move(spec), model, std::move(sets), seed, options, def.locomotion);
}

std::unique_ptr<SamiEnv> make_env(std::string_view name, std::string_view split, std::uint64_t seed,
                                  Options options) {
  const EnvId id = env_from_name(name);
  return make_env(id, task_sets(id, split), seed, nullptr, options);
}

}  // namespace cradle::sami

#include "sami/locomotion.h"

#include <algorithm>
#include <cmath>

namespace cradle::sami {
namespace {

enum class Reward { kCheetah, kAnt, kHopWalk, kSlim, kStandup };
enum class ObsForm { kVelQpos1, kVelQpos2, kCrippleAnt, kPlanar, kHumanoid };
enum class Scaling { kAll, kAntSplit, kMassOnly };
enum class Cripple { kNone, kJoint, kAntLeg };

// What differs between the locomotion envs.
struct Rules {
  Reward reward;
  ObsForm obs;
  Scaling scaling;
  Cripple cripple = Cripple::kNone;
  bool shrink = false;       // crippled capsules get half radius and half length
  double ctrl_cost = 0;      // weight of ||a||^2
  bool uniform_pos = false;  // reset noise on qpos: uniform(+-pos_noise), else normal
  bool uniform_vel = false;  // same for qvel
  double pos_noise = 0, vel_noise = 0;
  int first_cripple_geom = 0;  // geom of crippled joint 0 (joints: j + this)
};

// The crippled variant of a family: only the mass varies, `cripple` disables units from geom
// `first_geom` on (`shrink`: and halves their capsules).
Rules crippled(Rules r, Cripple cripple, int first_geom, bool shrink = false) {
  r.scaling = Scaling::kMassOnly;
  r.cripple = cripple;
  r.first_cripple_geom = first_geom;
  r.shrink = shrink;
  return r;
}

Rules rules(EnvId id) {
  // The families: reward, observation, control cost and reset noise.
  const Rules cheetah = {.reward = Reward::kCheetah,
                         .obs = ObsForm::kVelQpos1,
                         .scaling = Scaling::kAll,
                         .ctrl_cost = 0.1,
                         .pos_noise = 0.001,
                         .vel_noise = 0.001};
  const Rules ant = {.reward = Reward::kAnt,
                     .obs = ObsForm::kVelQpos2,
                     .scaling = Scaling::kAntSplit,
                     .ctrl_cost = 0.01,
                     .uniform_pos = true,
                     .pos_noise = 0.1,
                     .vel_noise = 0.1};
  const Rules planar = {.reward = Reward::kHopWalk,
                        .obs = ObsForm::kPlanar,
                        .scaling = Scaling::kAll,
                        .ctrl_cost = 1e-3,
                        .uniform_pos = true,
                        .uniform_vel = true,
                        .pos_noise = 0.005,
                        .vel_noise = 0.005};
  const Rules humanoid = {.reward = Reward::kSlim,
                          .obs = ObsForm::kHumanoid,
                          .scaling = Scaling::kAll,
                          .ctrl_cost = 0.1,
                          .uniform_pos = true,
                          .uniform_vel = true,
                          .pos_noise = 0.01,
                          .vel_noise = 0.01};
  switch (id) {
    case EnvId::kHalfCheetah:
      return cheetah;
    case EnvId::kCrippleHalfCheetah:
      return crippled(cheetah, Cripple::kJoint, 3);
    case EnvId::kAnt:
      return ant;
    case EnvId::kCrippleAnt: {
      Rules r = crippled(ant, Cripple::kAntLeg, 0, true);
      r.obs = ObsForm::kCrippleAnt;
      return r;
    }
    case EnvId::kHopper: {
      Rules r = planar;
      r.ctrl_cost = 0.1;
      return r;
    }
    case EnvId::kCrippleHopper:
    case EnvId::kCrippleWalker:
      return crippled(planar, Cripple::kJoint, 2);
    case EnvId::kWalker:
      return planar;
    case EnvId::kWalkerHopper:
      return crippled(planar, Cripple::kJoint, 2, true);
    case EnvId::kSlimHumanoid:
      return humanoid;
    case EnvId::kHumanoidStandup: {
      Rules r = humanoid;
      r.reward = Reward::kStandup;
      return r;
    }
    case EnvId::kPandaPush:
      break;
  }
  return {Reward::kCheetah, ObsForm::kVelQpos1, Scaling::kAll};
}

// Ant leg k (0-based, SaMI's numbering) -> its actuators and its thigh and lower-leg geoms.
constexpr int kAntLegActuators[4][2] = {{2, 3}, {4, 5}, {6, 7}, {0, 1}};
constexpr float kRed[4] = {1, 0, 0, 1};

class Locomotion final : public SamiEnv {
 public:
  Locomotion(Spec spec, ModelPtr model, std::vector<TaskSet> sets, std::uint64_t seed,
             Options options)
      : SamiEnv(std::move(spec), std::move(model), std::move(sets), seed),
        rules_(rules(spec_.id)),
        options_(options),
        mask_(spec_.action_size, 1.0),
        action_(spec_.action_size, 0.0) {}

  void reset(std::optional<std::uint64_t> seed) override {
    const TaskSet& set = begin_reset(seed);
    const mjModel* m = &model_;
    mjData* d = data_.get();
    // State: qpos0 and zero velocity plus the env's noise (Ant's quaternion included).
    for (int i = 0; i < m->nq; ++i) {
      d->qpos[i] =
          m->qpos0[i] + (rules_.uniform_pos ? rng_.uniform(-1, 1) : normal()) * rules_.pos_noise;
    }
    for (int i = 0; i < m->nv; ++i) {
      d->qvel[i] = (rules_.uniform_vel ? rng_.uniform(-1, 1) : normal()) * rules_.vel_noise;
    }
    // Hidden parameters, written into the private arrays only.
    info_.mass = pick(set.mass);
    info_.damping = pick(set.damping);
    scale(info_.mass, info_.damping);
    std::fill(mask_.begin(), mask_.end(), 1.0);
    if (!set.cripple.empty()) {
      const std::vector<int>& choice = set.cripple[rng_.next() % set.cripple.size()];
      info_.crippled.assign(choice.begin(), choice.end());
      std::sort(info_.crippled.begin(), info_.crippled.end());
      info_.masked = set.mask;
      for (int unit : info_.crippled) cripple(unit, set.mask);
    }
    mj_forward(m, d);
    x_before_ = forward_position();
    write_observation(0.0);
  }

  StepResult step(std::span<const double> action) override {
    check_action(action);
    const mjModel* m = &model_;
    mjData* d = data_.get();
    // The mask multiplies the action; MuJoCo clamps ctrl to ctrlrange itself.
    for (int i = 0; i < spec_.action_size; ++i) {
      action_[i] = action[i] * mask_[i];
      d->ctrl[i] = action_[i];
    }
    const double before = x_before_;
    for (int k = 0; k < spec_.frame_skip; ++k) mj_step(m, d);
    if (options_.contact_forces) mj_rnePostConstraint(m, d);
    x_before_ = forward_position();
    const double velocity = (x_before_ - before) / spec_.dt;
    double ctrl2 = 0;
    for (double a : action_) ctrl2 += a * a;
    StepResult out;
    out.reward = reward(velocity, ctrl2);
    info_.x_velocity = velocity;
    info_.steps++;
    out.truncated = info_.steps >= spec_.horizon;
    write_observation(velocity);
    return out;
  }

 private:
  // The x coordinate whose change is the forward velocity: root x, or the mass centre for
  // SlimHumanoid.
  double forward_position() const {
    if (rules_.reward != Reward::kSlim) return data_->qpos[0];
    double mx = 0, mass = 0;
    for (int b = 1; b < model_.nbody; ++b) {
      mx += model_.body_mass[b] * data_->xipos[3 * b];
      mass += model_.body_mass[b];
    }
    return mx / mass;
  }

  double reward(double velocity, double ctrl2) const {
    const mjData* d = data_.get();
    switch (rules_.reward) {
      case Reward::kCheetah:
        return velocity - rules_.ctrl_cost * ctrl2;
      case Reward::kAnt: {
        // cfrc_ext stays zero unless options_.contact_forces (as in the published runs).
        double contact = 0;
        for (int i = 0; i < 6 * model_.nbody; ++i) {
          const double f = std::clamp(d->cfrc_ext[i], -1.0, 1.0);
          contact += f * f;
        }
        return velocity - rules_.ctrl_cost * ctrl2 - 0.5 * contact + 1.0;
      }
      case Reward::kHopWalk:
        return velocity + 1.0 - rules_.ctrl_cost * ctrl2;
      case Reward::kSlim: {
        const double z = d->qpos[2];
        return 0.25 * velocity - rules_.ctrl_cost * ctrl2 + (z >= 1.0 && z <= 2.0 ? 5.0 : 0.0);
      }
      case Reward::kStandup: {
        double impact = 0;
        for (int i = 0; i < 6 * model_.nbody; ++i) impact += d->cfrc_ext[i] * d->cfrc_ext[i];
        return d->qpos[2] / model_.opt.timestep - rules_.ctrl_cost * ctrl2 -
               std::min(0.5e-6 * impact, 10.0) + 1.0;
      }
    }
    return 0;
  }

  // Mass and damping factors, per the env's rule (sami_models.md §2).
  void scale(double mass, double damping) {
    const mjModel* m = shared_.get();
    switch (rules_.scaling) {
      case Scaling::kAll:
        for (int b = 0; b < m->nbody; ++b) body_mass_[b] = m->body_mass[b] * mass;
        for (int v = 0; v < m->nv; ++v) dof_damping_[v] = m->dof_damping[v] * damping;
        break;
      case Scaling::kMassOnly:
        for (int b = 0; b < m->nbody; ++b) body_mass_[b] = m->body_mass[b] * mass;
        break;
      case Scaling::kAntSplit:
        // Bodies and dofs 2..7 times the factor, 8..13 divided by it: for bodies that is legs
        // 1-2 against 3-4, for dofs (which start with 6 root dofs) leg 1 against legs 2-4.
        for (int i = 2; i < 14; ++i) {
          body_mass_[i] = i < 8 ? m->body_mass[i] * mass : m->body_mass[i] / mass;
          dof_damping_[i] = i < 8 ? m->dof_damping[i] * damping : m->dof_damping[i] / damping;
        }
        break;
    }
  }

  // Cripples one joint (Ant: one leg): mask its actuators, colour its geoms red and, where the
  // env does so, halve the capsules' radius and half-length (the geom_pos copies of the
  // reference are inert in MuJoCo and are left out).
  void cripple(int unit, bool mask) {
    int actuators[2] = {unit, -1};
    int geoms[2] = {unit + rules_.first_cripple_geom, -1};
    if (rules_.cripple == Cripple::kAntLeg) {
      actuators[0] = kAntLegActuators[unit][0], actuators[1] = kAntLegActuators[unit][1];
      geoms[0] = 3 + 3 * unit, geoms[1] = 4 + 3 * unit;
    }
    for (int a : actuators) {
      if (a >= 0 && mask) mask_[a] = 0.0;
    }
    for (int g : geoms) {
      if (g < 0) continue;
      std::copy_n(kRed, 4, geom_rgba_.begin() + 4 * g);
      if (rules_.shrink) {
        geom_size_[3 * g] *= 0.5;
        geom_size_[3 * g + 1] *= 0.5;
      }
    }
  }

  void write_observation(double velocity) {
    const mjModel* m = &model_;
    const mjData* d = data_.get();
    double* o = obs_.data();
    auto put = [&](const mjtNum* src, int n) { o = std::copy_n(src, n, o); };
    switch (rules_.obs) {
      case ObsForm::kVelQpos1:
        *o++ = velocity;
        put(d->qpos + 1, m->nq - 1);
        put(d->qvel, m->nv);
        break;
      case ObsForm::kVelQpos2:
        *o++ = velocity;
        put(d->qpos + 2, m->nq - 2);
        put(d->qvel, m->nv);
        break;
      case ObsForm::kCrippleAnt:
        put(d->qpos, m->nq);
        put(d->qvel, m->nv);
        put(d->xmat + 9, 9);
        put(d->xpos + 3, 3);
        break;
      case ObsForm::kPlanar:
        put(d->qpos + 1, m->nq - 1);
        for (int i = 0; i < m->nv; ++i) *o++ = std::clamp(d->qvel[i], -10.0, 10.0);
        break;
      case ObsForm::kHumanoid:
        put(d->qpos + 2, m->nq - 2);
        put(d->qvel, m->nv);
        break;
    }
  }

  Rules rules_;
  Options options_;
  std::vector<double> mask_, action_;
  double x_before_ = 0;
};

}  // namespace

std::unique_ptr<SamiEnv> make_locomotion(Spec spec, ModelPtr model, std::vector<TaskSet> sets,
                                         std::uint64_t seed, Options options) {
  return std::make_unique<Locomotion>(std::move(spec), std::move(model), std::move(sets), seed,
                                      options);
}

}  // namespace cradle::sami

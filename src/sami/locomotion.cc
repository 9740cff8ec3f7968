#include "sami/locomotion.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace cradle::sami {
namespace {

enum class Reward { kCheetah, kAnt, kHopWalk, kSlim, kStandup };
// Where the forward term's x comes from: root x (qpos[0]) or the torso body's xpos as mj_step
// leaves it (computed at the start of the last substep, not recomputed: gym's get_body_com).
enum class Forward { kRootX, kTorsoXpos };
enum class ObsForm { kVelQpos1, kVelQpos2, kCrippleAnt, kPlanar, kHumanoid };
enum class Scaling { kAll, kAntSplit, kMassOnly };
enum class Cripple { kNone, kJoint, kAntLeg };

// What differs between the locomotion envs.
struct Rules {
  Reward reward;
  ObsForm obs;
  Scaling scaling;
  Forward forward = Forward::kRootX;
  Cripple cripple = Cripple::kNone;
  bool shrink = false;   // crippled capsules get half radius and half length
  double ctrl_cost = 0;  // weight of ||a||^2
  // ||a||^2 in float32, as NumPy computes it on the reference's float32 action; the crippled
  // envs multiply the action by a float64 mask first, so theirs is in float64.
  bool ctrl_cost_f32 = false;
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
  r.ctrl_cost_f32 = false;
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
                         .ctrl_cost_f32 = true,
                         .pos_noise = 0.001,
                         .vel_noise = 0.001};
  const Rules ant = {.reward = Reward::kAnt,
                     .obs = ObsForm::kVelQpos2,
                     .scaling = Scaling::kAntSplit,
                     .forward = Forward::kTorsoXpos,
                     .ctrl_cost = 0.01,
                     .ctrl_cost_f32 = true,
                     .uniform_pos = true,
                     .pos_noise = 0.1,
                     .vel_noise = 0.1};
  const Rules planar = {.reward = Reward::kHopWalk,
                        .obs = ObsForm::kPlanar,
                        .scaling = Scaling::kAll,
                        .ctrl_cost = 1e-3,
                        .ctrl_cost_f32 = true,
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

// np.sum's order of additions (NumPy 1.x pairwise summation, `pairwise_sum` in its loops): below
// 8 values one running sum from 0; up to 128, eight running sums combined as a tree, then the
// rest; above, the two halves (the first a multiple of 8 long) summed apart. The reference's costs
// are such sums, so the same order gives the same bits.
template <class T>
T numpy_sum(const T* x, int n) {
  if (n < 8) {
    T sum = 0;
    for (int i = 0; i < n; ++i) sum += x[i];
    return sum;
  }
  if (n <= 128) {
    T r[8];
    std::copy_n(x, 8, r);
    int i = 8;
    for (; i < n - n % 8; i += 8) {
      for (int j = 0; j < 8; ++j) r[j] += x[i + j];
    }
    T sum = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]));
    for (; i < n; ++i) sum += x[i];
    return sum;
  }
  int half = n / 2;
  half -= half % 8;
  return numpy_sum(x, half) + numpy_sum(x + half, n - half);
}

// The most squares a cost sums: 6 x nbody cfrc_ext entries (84 for the Ant and the humanoid).
constexpr int kMaxSquares = 6 * 32;

class Locomotion final : public SamiEnv {
 public:
  Locomotion(Spec spec, ModelPtr model, std::vector<TaskSet> sets, std::uint64_t seed,
             Options options)
      : SamiEnv(std::move(spec), std::move(model), std::move(sets), seed),
        rules_(rules(spec_.id)),
        options_(options),
        mask_(spec_.action_size, 1.0),
        action_(spec_.action_size, 0.0) {
    if (6 * model_.nbody > kMaxSquares) throw std::logic_error("locomotion: too many bodies");
  }

  void reset_episode(std::optional<std::uint64_t> seed) override {
    const TaskSet& set = begin_reset(seed);
    const mjModel* m = &model_;
    mjData* d = data_.get();
    // The reference writes the new parameters after set_state's mj_forward, so that forward (and
    // the solver's warm start it leaves for the first step) still sees the last episode's
    // parameters: put them back for it.
    apply(last_);
    // State: qpos0 and zero velocity plus the env's noise (Ant's quaternion included).
    for (int i = 0; i < m->nq; ++i) {
      d->qpos[i] =
          m->qpos0[i] + (rules_.uniform_pos ? rng_.uniform(-1, 1) : normal()) * rules_.pos_noise;
    }
    for (int i = 0; i < m->nv; ++i) {
      d->qvel[i] = (rules_.uniform_vel ? rng_.uniform(-1, 1) : normal()) * rules_.vel_noise;
    }
    // Hidden parameters of the new episode: drawn now (the generator's order is unchanged),
    // written after the forward.
    Draw draw;
    draw.mass = pick(set.mass);
    draw.damping = pick(set.damping);
    if (!set.cripple.empty()) {
      const std::vector<int>& choice = set.cripple[rng_.next() % set.cripple.size()];
      // validate() allows at most three units; kept ascending (a three-entry insertion sort).
      draw.crippled = static_cast<int>(std::min<size_t>(choice.size(), draw.units.size()));
      for (int k = 0; k < draw.crippled; ++k) {
        int u = choice[k], p = k;
        for (; p > 0 && draw.units[p - 1] > u; --p) draw.units[p] = draw.units[p - 1];
        draw.units[p] = u;
      }
      draw.mask = set.mask;
    }
    mj_forward(m, d);
    x_before_ = forward_position();
    restore_parameters();
    apply(draw);
    last_ = draw;
    info_.mass = draw.mass;
    info_.damping = draw.damping;
    info_.crippled.assign(draw.units.begin(), draw.units.begin() + draw.crippled);
    info_.masked = !set.cripple.empty() && set.mask;
    write_observation(0.0);
  }

  std::span<const double> action_mask() const override { return mask_; }

  StepResult step_episode(std::span<const double> action) override {
    check_action(action);
    const mjModel* m = &model_;
    mjData* d = data_.get();
    // The action is float32 in the reference (its action space's dtype, what its agents pass);
    // the mask multiplies it; MuJoCo clamps ctrl to ctrlrange itself.
    for (int i = 0; i < spec_.action_size; ++i) {
      action_[i] = static_cast<double>(static_cast<float>(action[i])) * mask_[i];
      d->ctrl[i] = action_[i];
    }
    const double before = x_before_;
    // SlimHumanoid pays for the root x-velocity of the state the step starts from, read from the
    // float32 observation (its index 22).
    const double start_vx = static_cast<float>(d->qvel[0]);
    for (int k = 0; k < spec_.frame_skip; ++k) mj_step(m, d);
    if (options_.contact_forces) mj_rnePostConstraint(m, d);
    x_before_ = forward_position();
    const double velocity = (x_before_ - before) / spec_.dt;
    StepResult out;
    out.reward = reward(velocity, start_vx);
    info_.x_velocity = rules_.reward == Reward::kSlim ? start_vx : velocity;
    info_.steps++;
    out.truncated = info_.steps >= spec_.horizon;
    write_observation(velocity);
    return out;
  }

 private:
  // One episode's hidden parameters (at most three crippled units).
  struct Draw {
    double mass = 1, damping = 1;
    std::array<int, 3> units{};
    int crippled = 0;
    bool mask = true;
  };

  // The x whose change over a step is the forward velocity.
  double forward_position() const {
    return rules_.forward == Forward::kTorsoXpos ? data_->xpos[3 * 1] : data_->qpos[0];
  }

  // sum(a^2) of the (masked) action as the reference computes it: in float32 on the float32
  // action, or in float64 (crippled envs, humanoids' data.ctrl), both in NumPy's order.
  double ctrl_squares() const {
    const int n = spec_.action_size;
    if (rules_.ctrl_cost_f32) {
      std::array<float, kMaxSquares> sq;
      for (int i = 0; i < n; ++i) {
        const float a = static_cast<float>(action_[i]);
        sq[i] = a * a;
      }
      return numpy_sum(sq.data(), n);
    }
    std::array<double, kMaxSquares> sq;
    for (int i = 0; i < n; ++i) sq[i] = action_[i] * action_[i];
    return numpy_sum(sq.data(), n);
  }

  // sum of squares of cfrc_ext, each entry clipped to [-1, 1] first when `clip`.
  double cfrc_squares(bool clip) const {
    const int n = 6 * model_.nbody;
    std::array<double, kMaxSquares> sq;
    for (int i = 0; i < n; ++i) {
      const double f = clip ? std::clamp(data_->cfrc_ext[i], -1.0, 1.0) : data_->cfrc_ext[i];
      sq[i] = f * f;
    }
    return numpy_sum(sq.data(), n);
  }

  // The reference's rewards term by term, in its order of operations (tma_sami.md §7.1). cfrc_ext
  // stays zero unless options_.contact_forces (as in the published runs).
  double reward(double velocity, double start_vx) const {
    const mjData* d = data_.get();
    const double ctrl = rules_.ctrl_cost * ctrl_squares();
    switch (rules_.reward) {
      case Reward::kCheetah:
        // The forward term is the float32 observation's first entry.
        return static_cast<double>(static_cast<float>(velocity)) - ctrl;
      case Reward::kAnt:
        return velocity - ctrl - 0.5 * cfrc_squares(true) + 1.0;
      case Reward::kHopWalk:
        return velocity + 1.0 - ctrl;
      case Reward::kSlim: {
        // 0.25 / 0.015 per m/s of the start's root x-velocity; the alive bonus needs the torso
        // between 1 and 2 m after the step; no termination.
        const double z = d->qpos[2];
        const double alive = (z < 1.0 || z > 2.0) ? 0.0 : 5.0;
        return (0.25 / 0.015) * start_vx - ctrl - 0.0 + alive;
      }
      case Reward::kStandup:
        return d->qpos[2] / model_.opt.timestep - ctrl -
               std::min(0.5e-6 * cfrc_squares(false), 10.0) + 1.0;
    }
    return 0;
  }

  // Puts the shared model's values back into the private arrays the parameters change.
  void restore_parameters() {
    const mjModel* m = shared_.get();
    std::copy_n(m->body_mass, body_mass_.size(), body_mass_.begin());
    std::copy_n(m->dof_damping, dof_damping_.size(), dof_damping_.begin());
    std::copy_n(m->geom_size, geom_size_.size(), geom_size_.begin());
    std::copy_n(m->geom_rgba, geom_rgba_.size(), geom_rgba_.begin());
  }

  // Writes one episode's parameters over the restored arrays and sets the action mask.
  void apply(const Draw& draw) {
    scale(draw.mass, draw.damping);
    std::fill(mask_.begin(), mask_.end(), 1.0);
    for (int i = 0; i < draw.crippled; ++i) cripple(draw.units[i], draw.mask);
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
      case Scaling::kAntSplit: {
        // Bodies and dofs 2..7 times the factor, 8..13 times its reciprocal (the reference
        // multiplies by 1.0 / factor, which differs from dividing by one ulp for some factors):
        // for bodies that is legs 1-2 against 3-4, for dofs (which start with 6 root dofs)
        // leg 1 against legs 2-4.
        const double inv_mass = 1.0 / mass, inv_damping = 1.0 / damping;
        for (int i = 2; i < 14; ++i) {
          body_mass_[i] = m->body_mass[i] * (i < 8 ? mass : inv_mass);
          dof_damping_[i] = m->dof_damping[i] * (i < 8 ? damping : inv_damping);
        }
        break;
      }
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
  Draw last_;  // the parameters in force (before the first episode: the model's own)
};

}  // namespace

std::unique_ptr<SamiEnv> make_locomotion(Spec spec, ModelPtr model, std::vector<TaskSet> sets,
                                         std::uint64_t seed, Options options) {
  return std::make_unique<Locomotion>(std::move(spec), std::move(model), std::move(sets), seed,
                                      options);
}

}  // namespace cradle::sami

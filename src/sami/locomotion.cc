#include "sami/locomotion.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace cradle::sami {
namespace {

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
             Options options, const LocomotionDef& def)
      : SamiEnv(std::move(spec), std::move(model), std::move(sets), seed),
        def_(def),
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
          m->qpos0[i] + (def_.uniform_pos ? rng_.uniform(-1, 1) : normal()) * def_.pos_noise;
    }
    for (int i = 0; i < m->nv; ++i) {
      d->qvel[i] = (def_.uniform_vel ? rng_.uniform(-1, 1) : normal()) * def_.vel_noise;
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
    const LocomotionStep done = {.model = m,
                                 .data = d,
                                 .velocity = velocity,
                                 .start_vx = start_vx,
                                 .ctrl = def_.ctrl_cost * ctrl_squares()};
    out.reward = def_.reward(done);
    info_.x_velocity = def_.info_start_vx ? start_vx : velocity;
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
    return def_.forward == Forward::kTorsoXpos ? data_->xpos[3 * 1] : data_->qpos[0];
  }

  // sum(a^2) of the (masked) action as the reference computes it: in float32 on the float32
  // action, or in float64 (crippled envs, humanoids' data.ctrl), both in NumPy's order.
  double ctrl_squares() const {
    const int n = spec_.action_size;
    if (def_.ctrl_cost_f32) {
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
    def_.scale(shared_.get(), &model_, draw.mass, draw.damping);
    std::fill(mask_.begin(), mask_.end(), 1.0);
    for (int i = 0; i < draw.crippled; ++i) cripple(draw.units[i], draw.mask);
  }

  // Cripples one joint (Ant: one leg): mask its actuators, colour its geoms red and, where the
  // env does so, halve the capsules' radius and half-length (the geom_pos copies of the
  // reference are inert in MuJoCo and are left out).
  void cripple(int unit, bool mask) {
    const CrippleParts parts = def_.cripple(unit);
    for (int a : parts.actuators) {
      if (a >= 0 && mask) mask_[a] = 0.0;
    }
    for (int g : parts.geoms) {
      if (g < 0) continue;
      std::copy_n(kRed, 4, geom_rgba_.begin() + 4 * g);
      if (def_.shrink) {
        geom_size_[3 * g] *= 0.5;
        geom_size_[3 * g + 1] *= 0.5;
      }
    }
  }

  void write_observation(double velocity) {
    def_.observe(&model_, data_.get(), velocity, obs_.data());
  }

  LocomotionDef def_;
  Options options_;
  std::vector<double> mask_, action_;
  double x_before_ = 0;
  Draw last_;  // the parameters in force (before the first episode: the model's own)
};

}  // namespace

double LocomotionStep::cfrc_squares(bool clip) const {
  const int n = 6 * model->nbody;
  std::array<double, kMaxSquares> sq;
  for (int i = 0; i < n; ++i) {
    const double f = clip ? std::clamp(data->cfrc_ext[i], -1.0, 1.0) : data->cfrc_ext[i];
    sq[i] = f * f;
  }
  return numpy_sum(sq.data(), n);
}

void scale_mass_and_damping(const mjModel* shared, mjModel* own, double mass, double damping) {
  for (int b = 0; b < shared->nbody; ++b) own->body_mass[b] = shared->body_mass[b] * mass;
  for (int v = 0; v < shared->nv; ++v) own->dof_damping[v] = shared->dof_damping[v] * damping;
}

void scale_mass(const mjModel* shared, mjModel* own, double mass, double /*damping*/) {
  for (int b = 0; b < shared->nbody; ++b) own->body_mass[b] = shared->body_mass[b] * mass;
}

std::unique_ptr<SamiEnv> make_locomotion(Spec spec, ModelPtr model, std::vector<TaskSet> sets,
                                         std::uint64_t seed, Options options,
                                         const LocomotionDef& def) {
  return std::make_unique<Locomotion>(std::move(spec), std::move(model), std::move(sets), seed,
                                      options, def);
}

}  // namespace cradle::sami

// Small MuJoCo tasks for the learner tests, built inline (header-only so several test files can
// include it).
//
// CartPole: an inverted pendulum, a hinged pole on a slider cart (1 m of track each way), pushed
// by a motor on the cart. Reward 1 per step; the episode terminates when the pole leans more
// than 0.2 rad or the state is not finite, and is truncated after max_steps. The observation is
// {"observation": [cart x, pole angle, cart velocity, pole angular velocity]} (float64), plus an
// optional 64x64x3 uint8 "eye" image (a pattern drawn from the state) to exercise the CNN path.
//
// Pendulum: a torque-driven pendulum to swing up and balance (Gymnasium's Pendulum-v1 dynamics
// in MJCF: a 1 m, 1 kg rod hinged at one end, g = 10, torque in [-2, 2], 0.05 s per step,
// angular velocity clipped to +-8 rad/s).
// Reward -(angle^2 + 0.1 velocity^2 + 0.001 torque^2) with the angle from upright in
// [-pi, pi]; episodes start at a random angle and are truncated after max_steps (never
// terminated). The observation is {"observation": [cos angle, sin angle, angular velocity]}.
#pragma once

#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/rng.h"
#include "envs/env.h"
#include "learn/vector_env.h"

namespace cradle::learn::testing {

inline constexpr char kCartPoleXml[] = R"(
<mujoco model="cartpole">
  <option timestep="0.02" integrator="RK4"/>
  <default>
    <geom contype="0" conaffinity="0"/>
  </default>
  <worldbody>
    <body name="cart">
      <joint name="slider" type="slide" axis="1 0 0" range="-1 1" limited="true"/>
      <geom type="box" size="0.1 0.1 0.05" mass="1"/>
      <body name="pole">
        <joint name="hinge" type="hinge" axis="0 1 0"/>
        <geom type="capsule" fromto="0 0 0 0.001 0 0.6" size="0.05" mass="0.5"/>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor joint="slider" gear="10" ctrlrange="-3 3" ctrllimited="true"/>
  </actuator>
</mujoco>
)";

// Compiles inline MJCF (through a virtual file system).
inline std::shared_ptr<const mjModel> compile_inline(const char* name, const char* xml,
                                                     size_t size) {
  char error[1000] = "";
  mjVFS vfs;
  mj_defaultVFS(&vfs);
  mj_makeEmptyFileVFS(&vfs, name, static_cast<int>(size));
  const int file = mj_findFileVFS(&vfs, name);
  std::copy(xml, xml + size, static_cast<char*>(vfs.filedata[file]));
  mjModel* model = mj_loadXML(name, &vfs, error, sizeof(error));
  mj_deleteVFS(&vfs);
  if (model == nullptr) throw std::runtime_error(std::string(name) + ": " + error);
  return {model, mj_deleteModel};
}

// What both tasks share: one compiled model (read-only), their own data and rng, a one-dimensional
// float32 action box and the step count of the episode.
class MujocoTask : public envs::Env {
 public:
  const DictSpace& observation_space() const override { return space_; }
  const Box& action_space() const override { return action_space_; }
  const envs::ObservationBuffers& observation() const override { return obs_; }
  const envs::Info& info() const override { return info_; }

  // A fresh episode from the task's random initial state.
  void reset(std::optional<std::uint64_t> seed) override {
    if (seed) rng_.seed_with(*seed);
    mj_resetData(model_.get(), data_.get());
    draw_initial_state();
    mj_forward(model_.get(), data_.get());
    info_.steps = 0;
    observe();
  }

 protected:
  MujocoTask(std::shared_ptr<const mjModel> model, DictSpace space, double max_action,
             int max_steps)
      : model_(std::move(model)),
        data_(mj_makeData(model_.get()), mj_deleteData),
        space_(std::move(space)),
        action_space_(Box::uniform({1}, DType::kFloat32, -max_action, max_action)),
        obs_(space_),
        max_steps_(max_steps) {}

  virtual void draw_initial_state() = 0;  // qpos and qvel, from rng_
  virtual void observe() = 0;             // obs_ from data_

  std::shared_ptr<const mjModel> model_;
  std::unique_ptr<mjData, void (*)(mjData*)> data_;
  DictSpace space_;
  Box action_space_;
  envs::ObservationBuffers obs_;
  envs::Info info_;
  Rng rng_;
  int max_steps_;
};

// `envs` tasks built from one compiled model, stepped in the calling thread.
template <typename Task, typename... Args>
std::unique_ptr<ThreadedVecEnv> make_tasks(int envs, const std::shared_ptr<const mjModel>& model,
                                           const Args&... args) {
  std::vector<std::unique_ptr<envs::Env>> list;
  for (int i = 0; i < envs; ++i) list.push_back(std::make_unique<Task>(model, args...));
  return std::make_unique<ThreadedVecEnv>(std::move(list), /*threads=*/1);
}

// One compiled model shared by every CartPole (read-only after loading).
inline std::shared_ptr<const mjModel> cartpole_model() {
  return compile_inline("cartpole.xml", kCartPoleXml, sizeof(kCartPoleXml));
}

class CartPole final : public MujocoTask {
 public:
  static constexpr double kMaxAngle = 0.2;  // rad
  static constexpr int kFrameSkip = 2;

  CartPole(std::shared_ptr<const mjModel> model, int max_steps, bool with_image)
      : MujocoTask(std::move(model), make_space(with_image), 3.0, max_steps),
        with_image_(with_image) {}

  envs::StepResult step(std::span<const double> action) override {
    data_->ctrl[0] = std::clamp(action[0], -3.0, 3.0);
    for (int i = 0; i < kFrameSkip; ++i) mj_step(model_.get(), data_.get());
    ++info_.steps;
    observe();
    const auto state = obs_.f64(0);
    const bool finite =
        std::all_of(state.begin(), state.end(), [](double v) { return std::isfinite(v); });
    envs::StepResult result{.reward = 1.0};
    result.terminated = !finite || std::fabs(data_->qpos[1]) > kMaxAngle;
    result.truncated = !result.terminated && info_.steps >= max_steps_;
    return result;
  }

 private:
  static DictSpace make_space(bool with_image) {
    DictSpace space;
    space.entries.push_back({"observation", Box::unbounded({4}, DType::kFloat64)});
    if (with_image)
      space.entries.push_back({"eye", Box::uniform({64, 64, 3}, DType::kUInt8, 0, 255)});
    return space;
  }

  void draw_initial_state() override {
    for (int i = 0; i < 2; ++i) {
      data_->qpos[i] = rng_.uniform(-0.01, 0.01);
      data_->qvel[i] = rng_.uniform(-0.01, 0.01);
    }
  }

  void observe() override {
    const std::span<double> state = obs_.f64(0);
    state[0] = data_->qpos[0];
    state[1] = data_->qpos[1];
    state[2] = data_->qvel[0];
    state[3] = data_->qvel[1];
    if (!with_image_) return;
    // A vertical bar whose column follows the pole tip, on a gradient.
    const std::span<std::uint8_t> image = obs_.u8(1);
    const int column =
        std::clamp(static_cast<int>(32 + 60 * (data_->qpos[0] + 0.6 * data_->qpos[1])), 0, 63);
    for (int y = 0; y < 64; ++y) {
      for (int x = 0; x < 64; ++x) {
        for (int c = 0; c < 3; ++c) {
          image[(y * 64 + x) * 3 + c] =
              static_cast<std::uint8_t>(std::abs(x - column) < 3 ? 255 : (x + y + 40 * c) % 128);
        }
      }
    }
  }

  bool with_image_;
};

// `envs` CartPoles stepped in the calling thread.
inline std::unique_ptr<ThreadedVecEnv> make_cartpoles(int envs, int max_steps,
                                                      bool with_image = false) {
  return make_tasks<CartPole>(envs, cartpole_model(), max_steps, with_image);
}

inline constexpr char kPendulumXml[] = R"(
<mujoco model="pendulum">
  <option timestep="0.01" gravity="0 0 -10" integrator="RK4"/>
  <worldbody>
    <body name="pole">
      <joint name="hinge" type="hinge" axis="0 1 0"/>
      <geom type="capsule" fromto="0 0 0 0 0 1" size="0.02" contype="0" conaffinity="0"/>
      <inertial pos="0 0 0.5" mass="1" diaginertia="0.083333 0.083333 0.0001"/>
    </body>
  </worldbody>
  <actuator>
    <motor joint="hinge" gear="1" ctrlrange="-2 2" ctrllimited="true"/>
  </actuator>
</mujoco>
)";

// One compiled model shared by every Pendulum.
inline std::shared_ptr<const mjModel> pendulum_model() {
  return compile_inline("pendulum.xml", kPendulumXml, sizeof(kPendulumXml));
}

class Pendulum final : public MujocoTask {
 public:
  static constexpr int kFrameSkip = 5;  // 0.05 s per step
  static constexpr double kMaxTorque = 2.0;
  static constexpr double kMaxSpeed = 8.0;  // rad/s, Gymnasium's clip

  Pendulum(std::shared_ptr<const mjModel> model, int max_steps)
      : MujocoTask(std::move(model), make_space(), kMaxTorque, max_steps) {}

  envs::StepResult step(std::span<const double> action) override {
    const double torque = std::clamp(action[0], -kMaxTorque, kMaxTorque);
    const double angle = std::remainder(data_->qpos[0], 2 * M_PI);  // from upright, [-pi, pi]
    const double velocity = data_->qvel[0];
    data_->ctrl[0] = torque;
    for (int i = 0; i < kFrameSkip; ++i) {
      mj_step(model_.get(), data_.get());
      data_->qvel[0] = std::clamp(data_->qvel[0], -kMaxSpeed, kMaxSpeed);
    }
    ++info_.steps;
    observe();
    envs::StepResult result{
        .reward = -(angle * angle + 0.1 * velocity * velocity + 0.001 * torque * torque)};
    result.truncated = info_.steps >= max_steps_;
    return result;
  }

 private:
  static DictSpace make_space() {
    DictSpace space;
    space.entries.push_back({"observation", Box::unbounded({3}, DType::kFloat64)});
    return space;
  }

  void draw_initial_state() override {
    data_->qpos[0] = rng_.uniform(-M_PI, M_PI);
    data_->qvel[0] = rng_.uniform(-1.0, 1.0);
  }

  void observe() override {
    const std::span<double> state = obs_.f64(0);
    state[0] = std::cos(data_->qpos[0]);
    state[1] = std::sin(data_->qpos[0]);
    state[2] = data_->qvel[0];
  }
};

// `envs` Pendulums stepped in the calling thread.
inline std::unique_ptr<ThreadedVecEnv> make_pendulums(int envs, int max_steps) {
  return make_tasks<Pendulum>(envs, pendulum_model(), max_steps);
}

}  // namespace cradle::learn::testing

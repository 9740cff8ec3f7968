#include "apps/tma_bench.h"

#include <box2d/box2d.h>

#include <chrono>
#include <cstring>
#include <span>
#include <vector>

#include "core/rng.h"
#include "tma/physics.h"

namespace cradle::apps {
namespace {

// Bitwise equality of every body's pose and velocity in two worlds built the same way.
bool same_world(const b2World& a, const b2World& b) {
  if (a.GetBodyCount() != b.GetBodyCount()) return false;
  const b2Body* x = a.GetBodyList();
  const b2Body* y = b.GetBodyList();
  for (; x != nullptr && y != nullptr; x = x->GetNext(), y = y->GetNext()) {
    const b2Transform& p = x->GetTransform();
    const b2Transform& q = y->GetTransform();
    const b2Vec2 v = x->GetLinearVelocity(), w = y->GetLinearVelocity();
    const float s = x->GetAngularVelocity(), t = y->GetAngularVelocity();
    if (std::memcmp(&p, &q, sizeof p) != 0 || std::memcmp(&v, &w, sizeof v) != 0 ||
        std::memcmp(&s, &t, sizeof s) != 0) {
      return false;
    }
  }
  return x == nullptr && y == nullptr;
}

struct TmaHooks {
  tma::TmaEnv& env;   // timed env
  tma::TmaEnv& bare;  // the same world, stepped bare
  Rng& rng;
  std::uint64_t seed;
  size_t width, motors;
  std::vector<double> actions;  // this segment's actions
  std::vector<float> commands;  // per step and motor: speed, max torque, limit on (1) or off (0)
  std::vector<double> episode;  // the episode's actions so far (for re-synchronising)
  long episode_steps = 0, segment = 0;
  std::uint64_t episode_index = 0;
  bool in_sync = true;

  void begin(long n) {
    for (size_t k = 0; k < static_cast<size_t>(n) * width; ++k) actions[k] = rng.uniform(-1, 1);
    if (!in_sync) {
      bare.reset(seed + episode_index);
      for (long i = 0; i < episode_steps; ++i) {
        bare.step(std::span<const double>(episode).subspan(static_cast<size_t>(i) * width, width));
      }
      in_sync = true;
    }
    segment = 0;
  }
  bool step(long i) {
    const auto action =
        std::span<const double>(actions).subspan(static_cast<size_t>(i) * width, width);
    const tma::TmaStep s = env.step(action);
    float* c = commands.data() + static_cast<size_t>(i) * 3 * motors;
    for (const tma::Motor& m : env.agent().motors) {
      *c++ = m.joint->GetMotorSpeed();
      *c++ = m.joint->GetMaxMotorTorque();
      *c++ = m.joint->IsLimitEnabled() ? 1.0f : 0.0f;
    }
    std::copy(action.begin(), action.end(),
              episode.begin() + static_cast<std::ptrdiff_t>(episode_steps * width));
    ++episode_steps;
    ++segment;
    return s.terminated || s.truncated;
  }
  void end() {}
  void replay() {
    b2World& world = bare.world();
    const std::vector<tma::Motor>& ms = bare.agent().motors;
    const float* c = commands.data();
    for (long i = 0; i < segment; ++i) {
      for (const tma::Motor& m : ms) {
        m.joint->SetMotorSpeed(c[0]);
        m.joint->SetMaxMotorTorque(c[1]);
        m.joint->EnableLimit(c[2] != 0);
        c += 3;
      }
      world.Step(static_cast<float>(1.0 / tma::kFps), tma::kVelocityIterations,
                 tma::kPositionIterations);
    }
  }
  bool exact() {
    in_sync = same_world(env.world(), bare.world());
    return in_sync;
  }
  void next_episode() {
    ++episode_index;
    env.reset(seed + episode_index);
    bare.reset(seed + episode_index);
    episode_steps = 0;
    in_sync = true;
  }
};

// The bench's task: stumps of height 1 every 3 m; a parkour with water, creepers and hills.
void set_bench_task(tma::TmaEnv& env, tma::EnvId id, const std::string& body) {
  if (id == tma::EnvId::kStumpTracks) {
    env.set_environment({{"stump_height", {1.0}}, {"obstacle_spacing", {3.0}}});
  } else {
    env.set_environment({{"input_vector", {-0.15, 0.8, 0.1}},
                         {"water_level", {body == "fish" ? 1.0 : 0.1}},
                         {"creepers_width", {0.25}},
                         {"creepers_height", {2.0}},
                         {"creepers_spacing", {2.5}}});
  }
}

}  // namespace

TmaBenchResult tma_bench(tma::EnvId id, const std::string& body, long steps, std::uint64_t seed,
                         int blocks) {
  using Clock = std::chrono::steady_clock;
  const tma::TmaOptions options{.env = id, .body = body};
  tma::TmaEnv env(options), bare(options);
  set_bench_task(env, id, body);
  set_bench_task(bare, id, body);
  TmaBenchResult r;
  const int resets = 20;
  const Clock::time_point t0 = Clock::now();
  for (int i = 0; i < resets; ++i) env.reset(seed + i);
  r.reset_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count() / resets;
  r.mass = env.agent().mass();

  const long block_steps = block_size(steps, blocks, 50);
  const size_t width = static_cast<size_t>(env.action_size());
  const size_t motors = env.agent().motors.size();
  Rng rng(seed + 1);
  TmaHooks hooks{
      .env = env,
      .bare = bare,
      .rng = rng,
      .seed = seed,
      .width = width,
      .motors = motors,
      .actions = std::vector<double>(static_cast<size_t>(block_steps) * width),
      .commands = std::vector<float>(static_cast<size_t>(block_steps) * 3 * motors),
      .episode = std::vector<double>(static_cast<size_t>(options.max_episode_steps + 1) * width)};
  env.reset(seed);
  bare.reset(seed);
  r.timing = time_blocks(steps, block_steps, hooks);
  const BlockTiming& t = r.timing;
  r.env_steps_per_s = steps / t.env_s;
  r.bare_steps_per_s = steps / t.bare_s;
  r.ratio = t.ratio.median;
  r.env_us = 1e6 * t.env_s / steps;
  r.bare_us = 1e6 * t.bare_s / steps;
  return r;
}

}  // namespace cradle::apps

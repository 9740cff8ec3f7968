// Cradle's TeachMyAgent envs against recorded runs of the reference code (TeachMyAgent ce15344 on
// box2d-py 2.3.10, 100 episodes per config, tests/tma/reference/): the same tasks and controllers
// run here, and the distributions of episode length, return and final head x (Welch's t-test) and
// of the terminated share (Fisher's exact test) must not differ at the 1 % level. Single episodes
// are not comparable (each implementation draws its stumps, clouds and initial push from its own
// generator). Also: the small statistics library those tests use, checked against scipy, and the
// Box2D 2.3 behaviours the envs reproduce on 2.4.1.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "tma/physics.h"
#include "tma/tma_env.h"
#include "tma/water.h"

namespace cradle::tma {
namespace {

// ---- Statistics -------------------------------------------------------------------------------

// Continued fraction of the incomplete beta function (modified Lentz).
double beta_fraction(double a, double b, double x) {
  constexpr double kTiny = 1e-300, kEps = 1e-15;
  const double qab = a + b, qap = a + 1, qam = a - 1;
  double c = 1, d = 1 - qab * x / qap;
  d = 1 / (std::abs(d) < kTiny ? kTiny : d);
  double h = d;
  for (int m = 1; m <= 1000; ++m) {
    const double m2 = 2.0 * m;
    for (const double aa : {m * (b - m) * x / ((qam + m2) * (a + m2)),
                            -(a + m) * (qab + m) * x / ((a + m2) * (qap + m2))}) {
      d = 1 + aa * d;
      d = 1 / (std::abs(d) < kTiny ? kTiny : d);
      c = 1 + aa / c;
      if (std::abs(c) < kTiny) c = kTiny;
      h *= d * c;
    }
    if (std::abs(d * c - 1) < kEps) break;
  }
  return h;
}

// The regularized incomplete beta function I_x(a, b).
double incomplete_beta(double a, double b, double x) {
  if (x <= 0) return 0;
  if (x >= 1) return 1;
  const double front = std::exp(std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) +
                                a * std::log(x) + b * std::log1p(-x));
  // The fraction converges fast on the side of the mean; the symmetry covers the other.
  if (x < (a + 1) / (a + b + 2)) return front * beta_fraction(a, b, x) / a;
  return 1 - front * beta_fraction(b, a, 1 - x) / b;
}

// Student's t distribution with `df` degrees of freedom: P(T <= t).
double student_t_cdf(double t, double df) {
  const double tail = 0.5 * incomplete_beta(df / 2, 0.5, df / (df + t * t));
  return t > 0 ? 1 - tail : tail;
}

// Welch's unequal-variance t-test, two-sided p-value (scipy's ttest_ind(equal_var=False)). Two
// constant samples give 1 when equal and 0 otherwise.
double welch_p(const std::vector<double>& a, const std::vector<double>& b) {
  auto moments = [](const std::vector<double>& v, double& mean, double& var) {
    mean = 0;
    for (double x : v) mean += x;
    mean /= v.size();
    var = 0;
    for (double x : v) var += (x - mean) * (x - mean);
    var /= v.size() - 1;
  };
  double ma, va, mb, vb;
  moments(a, ma, va);
  moments(b, mb, vb);
  const double sa = va / a.size(), sb = vb / b.size();
  if (sa + sb == 0) return ma == mb ? 1.0 : 0.0;
  const double t = (ma - mb) / std::sqrt(sa + sb);
  const double df =
      (sa + sb) * (sa + sb) / (sa * sa / (a.size() - 1.0) + sb * sb / (b.size() - 1.0));
  return 2 * student_t_cdf(-std::abs(t), df);
}

// Fisher's exact test on the 2 x 2 table [[a, b], [c, d]], two-sided: the probability, under the
// hypergeometric law of the table's margins, of every table no more likely than the one observed
// (scipy's fisher_exact, with its relative tolerance for ties).
double fisher_exact_p(int a, int b, int c, int d) {
  const int row = a + b, col = a + c, n = a + b + c + d;
  auto log_choose = [](int n, int k) {
    return std::lgamma(n + 1.0) - std::lgamma(k + 1.0) - std::lgamma(n - k + 1.0);
  };
  auto log_p = [&](int x) {
    return log_choose(col, x) + log_choose(n - col, row - x) - log_choose(n, row);
  };
  const double observed = log_p(a);
  double p = 0;
  for (int x = std::max(0, row + col - n); x <= std::min(row, col); ++x) {
    const double lp = log_p(x);
    if (lp <= observed + 1e-7) p += std::exp(lp);
  }
  return std::min(p, 1.0);
}

// Values from scipy 1.10 (scipy.special.betainc, scipy.stats.t, ttest_ind, fisher_exact).
TEST(TmaReferenceStats, IncompleteBetaAndStudentTMatchScipy) {
  EXPECT_NEAR(incomplete_beta(2.5, 3.5, 0.3), 0.2967529892956661, 1e-12);
  EXPECT_NEAR(incomplete_beta(10, 0.5, 0.95), 0.3171515754655451, 1e-12);
  EXPECT_NEAR(incomplete_beta(0.5, 0.5, 0.01), 0.06376856085851987, 1e-12);
  EXPECT_NEAR(student_t_cdf(-2.1, 7.3), 0.03612335671242664, 1e-12);
  EXPECT_NEAR(student_t_cdf(1.5, 150.0), 0.9321418721189644, 1e-12);
  EXPECT_NEAR(1 - student_t_cdf(8.0, 3.0), 0.0020382887938927333, 1e-12);
}

TEST(TmaReferenceStats, WelchMatchesScipy) {
  EXPECT_NEAR(welch_p({1.2, 3.4, 2.2, 5.1, 4.4, 3.3}, {6.1, 4.9, 7.2, 5.5, 8.0, 6.6, 7.7, 5.0}),
              0.0015679249262730971, 1e-12);
  EXPECT_NEAR(welch_p({1, 2, 3, 4}, {1.5, 2.5, 3.5, 4.5, 9}), 0.28773794648676465, 1e-12);
  EXPECT_EQ(welch_p({2000, 2000, 2000}, {2000, 2000}), 1.0);
  EXPECT_EQ(welch_p({2000, 2000, 2000}, {1999, 1999}), 0.0);
}

TEST(TmaReferenceStats, FisherExactMatchesScipy) {
  EXPECT_NEAR(fisher_exact_p(3, 97, 15, 85), 0.00519222290141669, 1e-12);
  EXPECT_NEAR(fisher_exact_p(72, 28, 83, 17), 0.08971151977366507, 1e-12);
  EXPECT_NEAR(fisher_exact_p(18, 82, 76, 24), 8.288023762257272e-17, 1e-25);
  EXPECT_NEAR(fisher_exact_p(3, 97, 100, 0), 3.906215373530251e-54, 1e-62);
  EXPECT_NEAR(fisher_exact_p(1, 9, 11, 3), 0.0027594561852200836, 1e-12);
  EXPECT_NEAR(fisher_exact_p(100, 0, 100, 0), 1.0, 1e-12);
}

// numpy's RandomState(seed).uniform(-1, 1): MT19937 seeded as std::mt19937(seed), 53-bit doubles
// from two 32-bit words.
class NumpyUniform {
 public:
  explicit NumpyUniform(std::uint32_t seed) : mt_(seed) {}
  double next() {
    const std::uint32_t a = mt_() >> 5, b = mt_() >> 6;
    return -1 + 2 * ((a * 67108864.0 + b) / 9007199254740992.0);
  }

 private:
  std::mt19937 mt_;
};

// numpy 1.24: RandomState(10005).uniform(-1, 1, 3), and the 700th value of RandomState(10000).
TEST(TmaReferenceStats, NumpyUniformStream) {
  NumpyUniform rng(10005);
  EXPECT_EQ(rng.next(), -0.905265994573625);
  EXPECT_EQ(rng.next(), -0.940244124611123);
  EXPECT_EQ(rng.next(), 0.9753077014454212);
  NumpyUniform other(10000);
  for (int i = 0; i < 699; ++i) other.next();
  EXPECT_EQ(other.next(), -0.8144394263873351);
}

// ---- Recorded reference runs ------------------------------------------------------------------

struct Sample {
  std::vector<double> length, episode_return, final_x;
  int terminated = 0;
};

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return s / v.size();
}

// Runs every recorded episode's task and controller on Cradle and compares the two samples.
void compare_with_reference(const std::string& config) {
  std::ifstream in(std::string(CRADLE_SOURCE_DIR) + "/tests/tma/reference/" + config + ".json");
  ASSERT_TRUE(in) << config;
  const nlohmann::json ref = nlohmann::json::parse(in);
  TmaOptions options;
  options.env = parse_env_id(ref["env"].get<std::string>());
  options.body = ref["embodiment"].get<std::string>();
  options.max_episode_steps = ref["max_steps"].get<int>();
  const bool sine = ref["controller"] == "sine";
  ASSERT_TRUE(sine || ref["controller"] == "random");
  TmaEnv env(options);
  const int n = env.action_size();
  std::vector<double> action(n);
  Sample theirs, ours;
  for (const nlohmann::json& episode : ref["episodes"]) {
    theirs.length.push_back(episode["length"].get<double>());
    theirs.episode_return.push_back(episode["episode_return"].get<double>());
    theirs.final_x.push_back(episode["final_head_x"].get<double>());
    theirs.terminated += episode["terminated"].get<bool>();

    std::vector<TaskParam> task;
    for (const auto& [name, value] : episode["task"].items()) {
      task.push_back({name, value.is_array() ? value.get<std::vector<double>>()
                                             : std::vector<double>{value.get<double>()}});
    }
    env.set_environment(task);
    const int seed = episode["seed"].get<int>();
    env.reset(seed);
    NumpyUniform rng(10000 + seed);
    int t = 0;
    TmaStep step;
    do {
      for (int i = 0; i < n; ++i) {
        // The sine gait: a travelling wave along the motors, odd ones a quarter period ahead.
        action[i] = sine ? std::sin(2 * std::numbers::pi * t / 40 + 2 * std::numbers::pi * i / n +
                                    (i % 2 ? std::numbers::pi / 2 : 0))
                         : rng.next();
      }
      step = env.step(action);
      ++t;
    } while (!step.terminated && !step.truncated);
    ours.length.push_back(t);
    ours.episode_return.push_back(env.episode_return());
    ours.final_x.push_back(env.agent().head->GetPosition().x);
    ours.terminated += step.terminated;
  }
  const int count = static_cast<int>(theirs.length.size());
  ASSERT_EQ(count, 100);
  const double p_length = welch_p(theirs.length, ours.length);
  const double p_return = welch_p(theirs.episode_return, ours.episode_return);
  const double p_x = welch_p(theirs.final_x, ours.final_x);
  const double p_terminated = fisher_exact_p(theirs.terminated, count - theirs.terminated,
                                             ours.terminated, count - ours.terminated);
  // One line per config for docs/fidelity.md: reference / Cradle means and the p-values.
  std::printf(
      "%s: length %.1f / %.1f (p %.3g), return %.2f / %.2f (p %.3g), final x %.2f / %.2f (p "
      "%.3g), terminated %d / %d %% (p %.3g)\n",
      config.c_str(), mean(theirs.length), mean(ours.length), p_length, mean(theirs.episode_return),
      mean(ours.episode_return), p_return, mean(theirs.final_x), mean(ours.final_x), p_x,
      theirs.terminated, ours.terminated, p_terminated);
  EXPECT_GE(p_length, 0.01) << config << ": episode length";
  EXPECT_GE(p_return, 0.01) << config << ": episode return";
  EXPECT_GE(p_x, 0.01) << config << ": final head x";
  EXPECT_GE(p_terminated, 0.01) << config << ": terminated share";
}

TEST(TmaReference, StumpTracksBipedalRandom) { compare_with_reference("st_bipedal_random"); }
TEST(TmaReference, StumpTracksSpiderRandom) { compare_with_reference("st_spider_random"); }
TEST(TmaReference, ParkourBipedalRandom) { compare_with_reference("pk_bipedal_random"); }
TEST(TmaReference, ParkourClimberRandom) { compare_with_reference("pk_climber_random"); }
// The fish swims only if a fin pinned at its limit stops pushing the water (box2d23_limits).
TEST(TmaReference, ParkourFishSine) { compare_with_reference("pk_fish_sine"); }
TEST(TmaReference, ParkourFishRandom) { compare_with_reference("pk_fish_random"); }

// ---- Box2D 2.3 behaviours reproduced on 2.4.1 ---------------------------------------------------

// A bar on a motorised revolute joint limited to [-0.5, 0.5] rad, about a static anchor.
struct Hinge {
  b2World world{b2Vec2(0, 0)};
  b2RevoluteJoint* joint = nullptr;
  b2Body* bar = nullptr;
  Hinge() {
    b2BodyDef def;
    b2Body* ground = world.CreateBody(&def);
    def.type = b2_dynamicBody;
    bar = world.CreateBody(&def);
    b2PolygonShape shape;
    shape.SetAsBox(0.5f, 0.05f, b2Vec2(0.5f, 0), 0);
    bar->CreateFixture(&shape, 1.0f);
    b2RevoluteJointDef jd;
    jd.Initialize(ground, bar, b2Vec2(0, 0));
    jd.enableLimit = true;
    jd.lowerAngle = -0.5f;
    jd.upperAngle = 0.5f;
    jd.enableMotor = true;
    jd.maxMotorTorque = 80;
    joint = static_cast<b2RevoluteJoint*>(world.CreateJoint(&jd));
  }
  void run(float speed, int steps, bool box2d23) {
    joint->SetMotorSpeed(speed);
    for (int t = 0; t < steps; ++t) {
      if (box2d23) box2d23_limits(world);
      world.Step(static_cast<float>(1 / kFps), kVelocityIterations, kPositionIterations);
    }
  }
};

// Box2D 2.3 holds a motor-driven joint past its limit, by up to b2_angularSlop (measured there:
// 0.026-0.033 rad); 2.4.1's own limit stops it at the limit. Driven back, it is inside at once.
TEST(TmaBox2d23Limits, MotorHeldJointRestsPastItsLimit) {
  Hinge hinge;
  hinge.run(6, 50, true);
  const float past = hinge.joint->GetJointAngle() - hinge.joint->GetUpperLimit();
  EXPECT_GT(past, 0.02f);
  EXPECT_LE(past, b2_angularSlop + 1e-4f);
  hinge.run(-6, 50, true);
  const float below = hinge.joint->GetLowerLimit() - hinge.joint->GetJointAngle();
  EXPECT_GT(below, 0.02f);
  EXPECT_LE(below, b2_angularSlop + 1e-4f);
  hinge.run(6, 1, true);
  EXPECT_GT(hinge.joint->GetJointAngle(), hinge.joint->GetLowerLimit());

  Hinge plain;  // 2.4.1's speculative limit
  plain.run(6, 50, false);
  EXPECT_NEAR(plain.joint->GetJointAngle(), 0.5f, 0.002f);
}

// A part whose wet area is at most b2_epsilon displaces no water but still gets drag: a unit box
// dipping 6e-8 into still water while sinking at 5 m/s is slowed by 0.25 * 1 * 5^2 = 6.25 N.
TEST(TmaWaterReference, SliverStillGetsDrag) {
  b2World world(b2Vec2(0, 0));
  b2BodyDef def;
  b2Body* pool = world.CreateBody(&def);
  b2PolygonShape water_shape;
  water_shape.SetAsBox(10, 5, b2Vec2(0, -5), 0);
  b2FixtureDef water_fd;
  water_fd.shape = &water_shape;
  water_fd.density = 1;
  water_fd.isSensor = true;
  b2Fixture* water = pool->CreateFixture(&water_fd);
  def.type = b2_dynamicBody;
  def.position.Set(0, 0.49999994f);  // bottom edge at -6e-8
  b2Body* box = world.CreateBody(&def);
  b2PolygonShape box_shape;
  box_shape.SetAsBox(0.5f, 0.5f);
  b2Fixture* part = box->CreateFixture(&box_shape, 1.0f);
  box->SetLinearVelocity(b2Vec2(0, -5));
  b2Vec2 wet[32];
  b2Vec2 poly[4], pool_poly[4];
  for (int k = 0; k < 4; ++k) {
    poly[k] = b2Mul(box->GetTransform(), box_shape.m_vertices[k]);
    pool_poly[k] = water_shape.m_vertices[k];
  }
  const int n = clip_polygon(pool_poly, 4, poly, 4, wet, 32);
  b2Vec2 centroid;
  ASSERT_GT(n, 2);
  EXPECT_EQ(polygon_area_centroid(wet, n, &centroid), 0.0);  // at most b2_epsilon
  apply_water_forces({{water, part}}, b2Vec2(0, -10), WaterParams{});
  world.Step(static_cast<float>(1 / kFps), kVelocityIterations, kPositionIterations);
  EXPECT_NEAR(box->GetLinearVelocity().y, -5 + 6.25 / kFps, 1e-4);
}

// The reference clips in doubles: against the whole-terrain water polygon (corners ~100 away) the
// wet part of a body far down the track keeps the body's corners and its crossings of the surface
// to a few float steps (in floats, cancellation moved a corner by 92 steps, 4.4e-5).
TEST(TmaWaterReference, ClippingKeepsFarBodiesExact) {
  const float surface = 5.2f;
  const b2Vec2 water[4] = {{0, -100}, {102.2f, -100}, {102.2f, surface}, {0, surface}};
  const b2Vec2 body[4] = {{87.13f, 4.91f}, {87.71f, 5.03f}, {87.65f, 5.57f}, {87.07f, 5.45f}};
  // The exact wet polygon's corners: the two submerged body corners and the two crossings.
  std::vector<std::array<long double, 2>> exact = {{body[0].x, body[0].y}, {body[1].x, body[1].y}};
  for (int s = 0; s < 4; ++s) {
    const b2Vec2 a = body[s], b = body[(s + 1) % 4];
    if ((a.y - surface) * (b.y - surface) > 0) continue;
    const long double u = (static_cast<long double>(surface) - a.y) / (b.y - a.y);
    exact.push_back({a.x + u * (static_cast<long double>(b.x) - a.x), surface});
  }
  ASSERT_EQ(exact.size(), 4u);
  b2Vec2 out[32];
  ASSERT_EQ(clip_polygon(water, 4, body, 4, out, 32), 4);
  auto steps = [](float value, long double target) {
    return std::abs(value - target) / (std::nextafter(std::abs(value), 1e30f) - std::abs(value));
  };
  for (const b2Vec2& p : std::span(out, 4)) {
    long double best = 1e30L;
    for (const auto& e : exact) best = std::min(best, std::max(steps(p.x, e[0]), steps(p.y, e[1])));
    EXPECT_LE(best, 4) << "wet corner " << p.x << ", " << p.y;
  }
}

// Stump Tracks records no gap after a stump that reaches the end of the track (the reference's
// loop stops there), so no ground point lies past the end.
TEST(TmaStumpsReference, NoGapAfterTheLastStump) {
  const double end = kTerrainLength * kTerrainStep;
  int reached = 0;
  for (double spacing = 0.5; spacing < 6; spacing += 0.25) {
    TmaEnv env(TmaOptions{.env = EnvId::kStumpTracks, .body = "old_classic_bipedal"});
    env.set_environment({{"stump_height", {1.0}}, {"obstacle_spacing", {spacing}}});
    env.reset(0);
    const Scene& scene = env.scene();
    const size_t stumps = scene.bodies.size();
    const double last_right = scene.xs[1 + 2 * (stumps - 1)] + kTerrainStep;
    const bool reaches = last_right >= end;
    reached += reaches;
    EXPECT_EQ(scene.xs.size(), 2 * stumps + (reaches ? 0 : 1)) << spacing;
    EXPECT_LT(scene.xs.back(), end) << spacing;
  }
  EXPECT_GT(reached, 0) << "no spacing put a stump at the end";
}

}  // namespace
}  // namespace cradle::tma

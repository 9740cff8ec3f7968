// Embodiments: spaces of every body in both environments, masses against tma_bodies.md §1.6,
// landing, determinism and one-line errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/rng.h"
#include "fixture.h"
#include "tma/tma_env.h"

namespace cradle::tma {
namespace {

struct Sizes {
  const char* body;
  int stump_obs, parkour_obs, actions;
};

constexpr Sizes kSizes[] = {
    {"old_classic_bipedal", 24, 36, 4},
    {"classic_bipedal", 24, 36, 4},
    {"small_bipedal", 24, 36, 4},
    {"amphibious_bipedal", 24, 36, 4},
    {"old_big_quadru", 34, 46, 8},
    {"spider", 42, 54, 12},
    {"millipede", 54, 66, 16},
    {"profile_chimpanzee", 50, 62, 14},
    {"climbing_profile_chimpanzee", 42, 54, 12},
    {"climbing_chest_profile_chimpanzee", 32, 44, 8},
    {"fish", 26, 38, 4},
    {"big_quadru", 34, 46, 8},
    {"wheel", 34, 46, 8},
};

TmaEnv make(EnvId env, const std::string& body) {
  return TmaEnv(TmaOptions{.env = env, .body = body});
}

TEST(TmaBodies, SpacesOfEveryEmbodimentInBothEnvironments) {
  EXPECT_EQ(std::size(kSizes), embodiment_names().size());
  for (const Sizes& s : kSizes) {
    TmaEnv stump = make(EnvId::kStumpTracks, s.body);
    EXPECT_EQ(stump.observation_size(), s.stump_obs) << s.body;
    EXPECT_EQ(stump.action_size(), s.actions) << s.body;
    TmaEnv parkour = make(EnvId::kParkour, s.body);
    EXPECT_EQ(parkour.observation_size(), s.parkour_obs) << s.body;
    EXPECT_EQ(parkour.action_size(), s.actions) << s.body;
    EXPECT_EQ(parkour.observation().size(), static_cast<size_t>(s.parkour_obs));
  }
}

// Part masses (density x area) of tma_bodies.md §1.6.
TEST(TmaBodies, MassesMatchTheSpec) {
  auto part_masses = [](const char* body) {
    TmaEnv env = make(EnvId::kStumpTracks, body);
    std::vector<double> m;
    for (const b2Body* b : env.agent().parts) m.push_back(b->GetMass());
    for (const Sensor& s : env.agent().sensors) m.push_back(s.body->GetMass());
    return m;
  };
  auto expect = [](const std::vector<double>& got, const std::vector<double>& want, const char* b) {
    ASSERT_EQ(got.size(), want.size()) << b;
    for (size_t i = 0; i < got.size(); ++i)
      EXPECT_NEAR(got[i], want[i], 2e-5) << b << " part " << i;
  };
  expect(part_masses("old_classic_bipedal"), {5.42222, 0.30222, 0.24178, 0.30222, 0.24178},
         "old_classic_bipedal");
  expect(part_masses("small_bipedal"), {5.42222, 0.15111, 0.12089, 0.15111, 0.12089},
         "small_bipedal");
  std::vector<double> spider = {2.22222};
  for (int k = 0; k < 4; ++k) spider.insert(spider.end(), {0.13333, 0.13333, 0.10667});
  expect(part_masses("spider"), spider, "spider");
  expect(part_masses("climbing_profile_chimpanzee"),
         {1.11111, 5.0, 0.24889, 0.19911, 0.24889, 0.19911, 0.24889, 0.19911, 0.035556, 0.24889,
          0.19911, 0.035556, 0.0078540, 0.0078540},
         "climbing_profile_chimpanzee");
  expect(part_masses("fish"), {0.84480, 0.36960, 0.22880, 0.05280, 0.04400}, "fish");
  // The amphibian: hull 1.25 and legs 0.25 times the water density.
  expect(part_masses("amphibious_bipedal"),
         {5.42222 / 4, 0.30222 / 4, 0.24178 / 4, 0.30222 / 4, 0.24178 / 4}, "amphibious_bipedal");
  // Inertia about the origin (used by the water push) and the hull's centre of mass.
  TmaEnv env = make(EnvId::kStumpTracks, "old_classic_bipedal");
  const b2Body* hull = env.agent().head;
  EXPECT_NEAR(hull->GetInertia(), 2.00174, 1e-4);
  EXPECT_NEAR(hull->GetLocalCenter().x, -0.02004, 1e-4);
}

// Walkers dropped over flat ground: both lower legs touch it within 50 steps.
TEST(TmaBodies, WalkersLandOnTheirLowerLegs) {
  for (const char* body : {"old_classic_bipedal", "classic_bipedal", "small_bipedal"}) {
    TmaEnv env = make(EnvId::kStumpTracks, body);
    env.set_environment({{"stump_height", {0.0}}, {"obstacle_spacing", {6.0}}});
    env.reset(3);
    const std::vector<double> zero(env.action_size(), 0.0);
    bool landed = false;
    for (int t = 0; t < 50 && !landed; ++t) {
      env.step(zero);
      const auto obs = env.observation();
      landed = obs[8] == 1.0 && obs[13] == 1.0;  // contact flags of lower(-1) and lower(+1)
    }
    EXPECT_TRUE(landed) << body;
  }
}

TEST(TmaBodies, SameSeedAndTaskGiveIdenticalTrajectories) {
  for (EnvId id : {EnvId::kStumpTracks, EnvId::kParkour}) {
    const char* body = id == EnvId::kStumpTracks ? "old_classic_bipedal" : "fish";
    std::vector<double> runs[2];
    for (auto& run : runs) {
      TmaEnv env = make(id, body);
      if (id == EnvId::kStumpTracks) {
        env.set_environment({{"stump_height", {1.0}}, {"obstacle_spacing", {2.0}}});
      } else {
        env.set_environment({{"input_vector", {-0.1, 0.8, 0.1}}, {"water_level", {0.9}}});
      }
      env.reset(42);
      Rng rng(7);
      std::vector<double> a(env.action_size());
      for (int t = 0; t < 200; ++t) {
        for (double& v : a) v = rng.uniform(-1, 1);
        const TmaStep r = env.step(a);
        run.insert(run.end(), env.observation().begin(), env.observation().end());
        run.push_back(r.reward);
      }
    }
    ASSERT_EQ(runs[0].size(), runs[1].size());
    EXPECT_EQ(0, std::memcmp(runs[0].data(), runs[1].data(), runs[0].size() * sizeof(double)));
  }
}

// The episode cap truncates (not terminates); success is "return so far > 230".
TEST(TmaBodies, EpisodeCapTruncates) {
  TmaEnv env(TmaOptions{.env = EnvId::kParkour, .body = "fish", .max_episode_steps = 25});
  env.set_environment({{"water_level", {1.0}}});
  env.reset(0);
  const std::vector<double> zero(4, 0.0);
  TmaStep r;
  for (int t = 0; t < 25; ++t) {
    EXPECT_FALSE(r.truncated);
    r = env.step(zero);
  }
  EXPECT_TRUE(r.truncated);
  EXPECT_FALSE(r.terminated);
  EXPECT_EQ(r.success, env.episode_return() > 230);
}

// Every wrong input is a UserError with a one-line message.
TEST(TmaBodies, BadInputsAreOneLineErrors) {
  auto one_line = [](auto&& f) {
    try {
      f();
    } catch (const UserError& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
      return std::string(e.what());
    }
    ADD_FAILURE() << "no UserError";
    return std::string();
  };
  EXPECT_NE(one_line([] { make(EnvId::kStumpTracks, "centipede"); }).find("centipede"),
            std::string::npos);
  EXPECT_NE(one_line([] { parse_env_id("hexagon-tracks"); }).find("hexagon"), std::string::npos);
  EXPECT_NE(one_line([] { TmaEnv(TmaOptions{.lidars = "sideways"}); }).find("sideways"),
            std::string::npos);
  TmaEnv stump = make(EnvId::kStumpTracks, "old_classic_bipedal");
  EXPECT_NE(one_line([&] {
              stump.set_environment({{"stump_height", {NAN}}});
            }).find("stump_height"),
            std::string::npos);
  EXPECT_NE(one_line([&] {
              stump.set_environment({{"stump_height", {12.0}}});
            }).find("range"),
            std::string::npos);
  one_line([&] { stump.set_environment({{"water_level", {0.5}}}); });
  one_line([&] { stump.set_environment({{"obstacle_spacing", {1.0, 2.0}}}); });
  EXPECT_NE(one_line([&] { stump.step(std::vector<double>(3, 0.0)); }).find("expected 4"),
            std::string::npos);
  one_line([&] { stump.step(std::vector<double>{0, NAN, 0, 0}); });
  TmaEnv parkour = make(EnvId::kParkour, "fish");
  one_line([&] { parkour.set_environment({{"input_vector", {0.0, 0.0}}}); });
  one_line([&] { parkour.set_environment({{"water_level", {-0.5}}}); });
  one_line([&] { parkour.set_environment({{"terrain_cppn_scale", {1.0}}}); });
  one_line([&] { parkour.set_environment({{"creepers_height", {INFINITY}}}); });
  // A failed call leaves the task unchanged.
  EXPECT_EQ(parkour.parkour_task().water_level, 0.0);
}

// ---- The reference's body and Parkour options ----

TmaOptions with(EnvId env, const std::string& body,
                std::initializer_list<std::pair<const char*, const char*>> options) {
  TmaOptions o{.env = env, .body = body};
  for (const auto& [name, value] : options) set_option(o, name, value);
  return o;
}

// motors_torque replaces the body's torque: a motor's max torque is torque * |a|.
TEST(TmaOptions, MotorsTorqueScalesTheMotors) {
  for (const char* body : {"classic_bipedal", "climbing_profile_chimpanzee", "fish"}) {
    TmaEnv plain(TmaOptions{.env = EnvId::kParkour, .body = body});
    TmaEnv strong(with(EnvId::kParkour, body, {{"motors_torque", "250"}}));
    EXPECT_EQ(strong.agent().torque, 250.0) << body;
    EXPECT_NE(plain.agent().torque, 250.0) << body;
    std::vector<double> action(strong.action_size(), 0.4);
    plain.step(action);
    strong.step(action);
    EXPECT_FLOAT_EQ(strong.agent().motors[0].joint->GetMaxMotorTorque(), 250 * 0.4f) << body;
    EXPECT_FLOAT_EQ(plain.agent().motors[0].joint->GetMaxMotorTorque(),
                    static_cast<float>(plain.agent().torque * 0.4))
        << body;
  }
}

// nb_of_bodies: segments of the millipede, each with a pair of two-part legs (5 parts, 4 motors,
// 10 motor observations); the torque penalty is shared out; the body's width sets the start pad.
TEST(TmaOptions, NbOfBodiesSizesTheMillipede) {
  for (int bodies : {1, 4, 7, 12}) {
    TmaEnv env(
        with(EnvId::kStumpTracks, "millipede", {{"nb_of_bodies", std::to_string(bodies).c_str()}}));
    EXPECT_EQ(env.action_size(), 4 * bodies);
    EXPECT_EQ(env.observation_size(), 4 + 10 + 10 * bodies);
    EXPECT_EQ(env.agent().parts.size(), static_cast<size_t>(5 * bodies));
    EXPECT_DOUBLE_EQ(env.agent().torque_penalty, 3.5e-4 / bodies);
    // Start pad: max(20, width / TERRAIN_STEP + 5) steps, width = 20 px per segment.
    const double pad = std::max(20.0, bodies * 20.0 / 14.0 + 5);
    EXPECT_FLOAT_EQ(env.spawn().x, static_cast<float>(kTerrainStep * pad / 2)) << bodies;
    TmaEnv parkour(
        with(EnvId::kParkour, "millipede", {{"nb_of_bodies", std::to_string(bodies).c_str()}}));
    EXPECT_DOUBLE_EQ(parkour.finish_x(), (kTerrainLength + pad - 5) * kTerrainStep);
    EXPECT_EQ(parkour.observation_size(), 6 + 20 + 10 * bodies);
  }
}

// nb_pairs_of_legs: the spider's legs (three parts and three motors each, 2 + 2 + 3 observations).
TEST(TmaOptions, NbPairsOfLegsSizesTheSpider) {
  for (int pairs : {1, 2, 3, 5}) {
    TmaEnv env(
        with(EnvId::kStumpTracks, "spider", {{"nb_pairs_of_legs", std::to_string(pairs).c_str()}}));
    EXPECT_EQ(env.action_size(), 6 * pairs);
    EXPECT_EQ(env.observation_size(), 4 + 10 + 14 * pairs);
    EXPECT_EQ(env.agent().parts.size(), static_cast<size_t>(1 + 6 * pairs));
    EXPECT_DOUBLE_EQ(env.agent().torque_penalty, 3.5e-4 / pairs);
  }
}

// Parkour counts the steps under / out of water; past the limit the agent is dead: observation
// [5] = 1 and every action forced to 0, and the episode goes on.
TEST(TmaOptions, WaterStepLimitsKillTheAgent) {
  struct Case {
    const char* body;
    const char* option;
    double water_level;  // 0: the body stays out of water, 1: under it
  };
  for (const Case& c : {Case{"fish", "nb_steps_outside_water", 0.0},
                        Case{"classic_bipedal", "nb_steps_under_water", 1.0},
                        Case{"climbing_profile_chimpanzee", "nb_steps_under_water", 1.0}}) {
    for (int limit : {0, 5, 12}) {
      TmaEnv env(with(EnvId::kParkour, c.body, {{c.option, std::to_string(limit).c_str()}}));
      env.set_environment({{"water_level", {c.water_level}}});
      env.reset(3);
      const std::vector<double> push(env.action_size(), 1.0);
      // After k steps the counter is k; the step that starts with it above the limit is dead.
      for (int k = 1; k <= limit + 2; ++k) {
        const TmaStep r = env.step(push);
        const bool dead = k == limit + 2;
        EXPECT_EQ(env.dead(), dead) << c.body << " limit " << limit << " step " << k;
        EXPECT_EQ(env.observation()[5], dead ? 1.0 : 0.0) << c.body << " step " << k;
        if (dead) {
          EXPECT_EQ(env.agent().motors[0].joint->GetMaxMotorTorque(), 0.0f) << c.body;
          EXPECT_FALSE(r.terminated) << c.body;
        }
      }
    }
    // The default limit (600) is far off.
    TmaEnv plain(TmaOptions{.env = EnvId::kParkour, .body = c.body});
    plain.set_environment({{"water_level", {c.water_level}}});
    plain.reset(3);
    const std::vector<double> push(plain.action_size(), 1.0);
    for (int k = 0; k < 20; ++k) plain.step(push);
    EXPECT_FALSE(plain.dead()) << c.body;
    EXPECT_EQ(c.water_level > 0 ? plain.steps_under_water() : plain.steps_outside_water(), 20);
  }
}

// ceiling_offset sets the start pad's ceiling (and the climbers' hanging height);
// ceiling_clip_offset keeps the ceiling that far above the ground. Both in CPPN units.
TEST(TmaOptions, CeilingOffsetsMoveTheCeiling) {
  for (double scale : {10.0, 20.0}) {
    TmaEnv env(with(EnvId::kParkour, "classic_bipedal", {{"ceiling_offset", "120"}}));
    env.set_environment({{"terrain_cppn_scale", {scale}}});
    env.reset(0);
    TmaEnv plain(TmaOptions{.env = EnvId::kParkour, .body = "classic_bipedal"});
    plain.set_environment({{"terrain_cppn_scale", {scale}}});
    plain.reset(0);
    EXPECT_DOUBLE_EQ(env.scene().ceiling[0], kTerrainHeight + 120 / scale);
    EXPECT_DOUBLE_EQ(plain.scene().ceiling[0], kTerrainHeight + 200 / scale);
    // Every point moves down by the difference, clipped at the ground (clip offset 0).
    const Scene &lo = env.scene(), &hi = plain.scene();
    int moved = 0;
    for (size_t i = 0; i < lo.ceiling.size(); ++i) {
      EXPECT_NEAR(lo.ceiling[i], std::max(hi.ceiling[i] - 80 / scale, lo.ground[i]), 1e-9) << i;
      moved += std::abs(hi.ceiling[i] - lo.ceiling[i] - 80 / scale) < 1e-9;
    }
    EXPECT_GT(moved, 100);
    EXPECT_EQ(lo.ground, hi.ground);
  }
  // Clip: a ceiling started at the ground stays 30 / 10 = 3 units above it, touching in places.
  TmaEnv clipped(with(EnvId::kParkour, "classic_bipedal",
                      {{"ceiling_offset", "0"}, {"ceiling_clip_offset", "30"}}));
  const Scene& s = clipped.scene();
  int at_clip = 0;
  for (size_t i = 20; i < s.ground.size(); ++i) {
    EXPECT_GE(s.ceiling[i], s.ground[i] + 3.0 - 1e-12) << i;
    at_clip += s.ceiling[i] == s.ground[i] + 3.0;
  }
  EXPECT_GT(at_clip, 0);
  // A climber hangs from the start pad's ceiling: 20 - 12 = 8 units lower with an offset of 120.
  TmaEnv high(TmaOptions{.env = EnvId::kParkour, .body = "climbing_profile_chimpanzee"});
  TmaEnv low(with(EnvId::kParkour, "climbing_profile_chimpanzee", {{"ceiling_offset", "120"}}));
  EXPECT_NEAR(high.agent().head->GetPosition().y - low.agent().head->GetPosition().y, 8.0, 0.05);
}

// Writes `weights` as a raw float32 file.
void write_floats(const std::filesystem::path& file, const std::vector<float>& weights) {
  std::ofstream out(file, std::ios::binary);
  out.write(reinterpret_cast<const char*>(weights.data()),
            static_cast<std::streamsize>(weights.size() * sizeof(float)));
}

std::vector<float> read_floats(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary | std::ios::ate);
  std::vector<float> w(static_cast<size_t>(in.tellg()) / sizeof(float));
  in.seekg(0);
  in.read(reinterpret_cast<char*>(w.data()), static_cast<std::streamsize>(w.size() * 4));
  return w;
}

// CPPN_weights_path: a user's weights, as a raw file or a TensorFlow checkpoint prefix.
TEST(TmaOptions, CppnWeightsFromAUserFile) {
  const std::filesystem::path dir = test::fresh_dir("tma_cppn");
  std::vector<float> w = read_floats(data_dir() / "ground_ceiling_cppn.f32");
  ASSERT_EQ(w.size(), 12672u);
  // The output layer (the last 64 x 2) doubled: every output doubles, exactly in float32.
  for (size_t i = w.size() - 128; i < w.size(); ++i) w[i] *= 2;
  write_floats(dir / "double.f32", w);
  std::filesystem::create_directories(dir / "ckpt");
  write_floats(dir / "ckpt" / ".data-00000-of-00001", w);
  write_floats(dir / "model.data-00000-of-00001", w);

  TmaEnv plain(TmaOptions{.env = EnvId::kParkour, .body = "classic_bipedal"});
  const std::vector<double> g = plain.scene().ground;
  for (const std::string& path :
       {(dir / "double.f32").string(), (dir / "ckpt").string() + "/", (dir / "model").string()}) {
    TmaOptions o{.env = EnvId::kParkour, .body = "classic_bipedal"};
    set_option(o, "CPPN_weights_path", path);
    TmaEnv env(o);
    const std::vector<double>& g2 = env.scene().ground;
    ASSERT_EQ(g2.size(), g.size());
    int moved = 0;
    for (size_t i = 0; i < g.size(); ++i) {
      EXPECT_NEAR(g2[i] - kTerrainHeight, 2 * (g[i] - kTerrainHeight), 1e-9) << path << " " << i;
      moved += std::abs(g[i] - kTerrainHeight) > 1e-3;
    }
    EXPECT_GT(moved, 100) << path;
  }
  // input_CPPN_dim: a CPPN over 5 task inputs (6 x 64 first layer); the task's input vector
  // then has 5 values.
  Rng rng(4);
  std::vector<float> w5((6 + 3 * 64 + 2) * 64);
  for (float& v : w5) v = static_cast<float>(rng.uniform(-1, 1));
  write_floats(dir / "five.f32", w5);
  TmaEnv five(with(EnvId::kParkour, "classic_bipedal",
                   {{"CPPN_weights_path", (dir / "five.f32").c_str()}, {"input_CPPN_dim", "5"}}));
  EXPECT_EQ(five.parkour_task().input_vector.size(), 5u);
  const std::vector<double> zeros = five.scene().ground;
  five.set_environment({{"input_vector", {0.5, -0.5, 0.2, 0.9, -1.0}}});
  five.reset(0);
  EXPECT_NE(five.scene().ground, zeros);
  EXPECT_THROW(five.set_environment({{"input_vector", {0.0, 0.0, 0.0}}}), UserError);
  std::filesystem::remove_all(dir);
}

// Every wrong option is a one-line UserError naming the option (an unknown one lists them all).
TEST(TmaOptions, WrongOptionsAreOneLineErrors) {
  auto message = [](auto&& f) {
    try {
      f();
    } catch (const UserError& e) {
      const std::string m = e.what();
      EXPECT_EQ(m.find('\n'), std::string::npos) << m;
      return m;
    }
    ADD_FAILURE() << "no UserError";
    return std::string();
  };
  auto has = [](const std::string& m, const char* part) {
    EXPECT_NE(m.find(part), std::string::npos) << m << " (expected '" << part << "')";
  };
  TmaOptions o;
  const std::string unknown = message([&] { set_option(o, "nb_of_legs", "4"); });
  has(unknown, "nb_of_legs");
  for (const std::string& name : option_names()) has(unknown, name.c_str());
  has(message([&] { set_option(o, "nb_of_bodies", "2.5"); }), "nb_of_bodies");
  has(message([&] { set_option(o, "nb_of_bodies", "0"); }), "integer in [1, 100]");
  has(message([&] { set_option(o, "nb_pairs_of_legs", "two"); }), "nb_pairs_of_legs");
  has(message([&] { set_option(o, "motors_torque", "-3"); }), "motors_torque");
  has(message([&] { set_option(o, "motors_torque", "nan"); }), "motors_torque");
  has(message([&] { set_option(o, "nb_steps_under_water", "-1"); }), "nb_steps_under_water");
  has(message([&] { set_option(o, "ceiling_offset", "inf"); }), "ceiling_offset");
  has(message([&] { set_option(o, "input_CPPN_dim", "3x"); }), "input_CPPN_dim");
  set_option(o, "nb_steps_under_water", "600.0");  // run.py parses these as floats
  EXPECT_EQ(o.nb_steps_under_water, 600);
  // Options the body or the env does not take.
  has(message([] {
        TmaEnv(with(EnvId::kStumpTracks, "spider", {{"nb_of_bodies", "3"}}));
      }),
      "millipede");
  has(message([] {
        TmaEnv(with(EnvId::kStumpTracks, "millipede", {{"nb_pairs_of_legs", "3"}}));
      }),
      "spider");
  has(message([] {
        TmaEnv(with(EnvId::kParkour, "classic_bipedal", {{"nb_steps_outside_water", "3"}}));
      }),
      "nb_steps_outside_water");
  has(message([] {
        TmaEnv(with(EnvId::kParkour, "fish", {{"nb_steps_under_water", "3"}}));
      }),
      "nb_steps_under_water");
  has(message([] {
        TmaEnv(with(EnvId::kParkour, "amphibious_bipedal", {{"nb_steps_under_water", "3"}}));
      }),
      "amphibious_bipedal");
  has(message([] {
        TmaEnv(with(EnvId::kStumpTracks, "spider", {{"ceiling_offset", "100"}}));
      }),
      "Parkour");
  has(message([] {
        TmaEnv(with(EnvId::kParkour, "spider", {{"input_CPPN_dim", "2"}}));
      }),
      "CPPN_weights_path");
  // A missing or malformed weight file.
  has(message([] {
        TmaEnv(with(EnvId::kParkour, "spider", {{"CPPN_weights_path", "/nonexistent/cppn.f32"}}));
      }),
      "/nonexistent/cppn.f32");
  const std::filesystem::path dir = test::fresh_dir("tma_bad_cppn");
  write_floats(dir / "short.f32", std::vector<float>(1000, 0.5f));
  has(message([&] {
        TmaEnv(
            with(EnvId::kParkour, "spider", {{"CPPN_weights_path", (dir / "short.f32").c_str()}}));
      }),
      "50688");
  std::filesystem::remove_all(dir);
}

// `cradle tma random` (and `run`) take run.py's flags; a wrong one is a one-line error.
TEST(TmaOptions, CliTakesRunPyFlags) {
  auto episode = [](const std::string& flags) {
    const test::RunResult r =
        test::run_cradle("tma random --env parkour --task water_level=0 --steps 40 " + flags);
    EXPECT_EQ(r.status, 0) << flags << ": " << r.out;
    return r.out;
  };
  const std::string plain = episode("--embodiment millipede");
  EXPECT_NE(plain.find("40 steps"), std::string::npos) << plain;
  // Torque 0: the legs go limp, so the same seed's episode gets another return.
  EXPECT_NE(episode("--embodiment millipede --motors_torque 0"), plain);
  EXPECT_EQ(episode("--embodiment millipede --motors_torque 200"), plain);  // its default
  EXPECT_EQ(episode("--embodiment millipede --nb_of_bodies 4"), plain);
  EXPECT_NE(episode("--embodiment millipede --nb_of_bodies 6"), plain);
  // Under water (level 1), a limit of 0 steps leaves the millipede dead from its second step.
  EXPECT_NE(episode("--embodiment millipede --task water_level=1 --under_water 0"),
            episode("--embodiment millipede --task water_level=1"));
  for (const char* flags :
       {"--embodiment millipede --nb_of_bodies 2.5", "--embodiment fish --under_water 3",
        "--embodiment spider --nb_of_bodies 3", "--embodiment fish --input_CPPN_dim 2",
        "--embodiment fish --CPPN_weights_path /nonexistent/w.f32"}) {
    const test::RunResult r = test::run_cradle(std::string("tma random --env parkour ") + flags);
    EXPECT_EQ(r.status, 1) << flags;
    EXPECT_EQ(r.out.rfind("cradle: error: ", 0), 0u) << flags << ": " << r.out;
    EXPECT_EQ(r.out.find('\n'), r.out.size() - 1) << flags << ": " << r.out;
  }
}

}  // namespace
}  // namespace cradle::tma

// Embodiments: spaces of every body in both environments, masses against tma_bodies.md §1.6,
// landing, determinism and one-line errors.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/rng.h"
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

}  // namespace
}  // namespace cradle::tma

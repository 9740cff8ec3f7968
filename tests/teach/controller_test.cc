// TeacherController: bounds formats, shuffling, reward scaling, test sets, books.
#include "teach/controller.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

#include "core/error.h"

namespace cradle::teach {
namespace {

// A teacher that proposes a scripted task and records what it is told.
class ScriptedTeacher : public Teacher {
 public:
  ScriptedTeacher(std::vector<float> mins, std::vector<float> maxs, Task next)
      : Teacher(std::move(mins), std::move(maxs), 1), next_(std::move(next)) {}
  Task sample_task() override {
    ++samples;
    return next_;
  }
  void step_update(const std::vector<float>&, const std::vector<float>&, double,
                   const std::vector<float>&, bool) override {
    ++steps;
  }
  void episodic_update(const Task& task, double ret, bool success) override {
    tasks.push_back(task);
    returns.push_back(ret);
    successes.push_back(success);
  }
  const char* name() const override { return "Scripted"; }

  Task next_;
  int samples = 0, steps = 0;
  std::vector<Task> tasks;
  std::vector<double> returns;
  std::vector<bool> successes;
};

// The shipped Stump Tracks test set.
const std::filesystem::path kStumpsSet =
    std::filesystem::path(CRADLE_SOURCE_DIR) / "data/teachmyagent/parametric_stumps_test_set.csv";

TaskSpace parkour_like() {
  return TaskSpace::from_json(nlohmann::ordered_json::parse(
      R"({"input_vector": [[-0.35, 0.05], [0.6, 1.0], [-0.1, 0.3]], "water_level": [0, 1],
          "creepers": [0, 4, 2]})"));
}

TEST(TaskSpace, FlattensTheThreeFormatsInOrder) {
  const TaskSpace space = parkour_like();
  ASSERT_EQ(space.dims(), 6);
  EXPECT_EQ(space.dim_names(),
            (std::vector<std::string>{"input_vector_0", "input_vector_1", "input_vector_2",
                                      "water_level", "creepers_0", "creepers_1"}));
  EXPECT_EQ(space.mins(), (std::vector<float>{-0.35f, 0.6f, -0.1f, 0, 0, 0}));
  EXPECT_EQ(space.maxs(), (std::vector<float>{0.05f, 1.0f, 0.3f, 1, 4, 4}));
  const nlohmann::ordered_json b = space.bounds_json();
  EXPECT_EQ(b["names"].size(), 6u);
  EXPECT_EQ(b["mins"].size(), 6u);
}

TEST(TaskSpace, VectorAndNamedParametersRoundTrip) {
  const TaskSpace space = parkour_like();
  const Task t = {-0.1f, 0.7f, 0.2f, 0.5f, 1.5f, 3.f};
  const auto params = space.to_params(t);
  ASSERT_EQ(params.size(), 3u);
  EXPECT_EQ(params[0].first, "input_vector");
  EXPECT_EQ(params[0].second.size(), 3u);
  EXPECT_EQ(params[1].first, "water_level");
  EXPECT_EQ(params[1].second, std::vector<double>{0.5});
  EXPECT_EQ(params[2].second, (std::vector<double>{1.5, 3.0}));
  EXPECT_EQ(space.from_params(params), t);
}

TEST(TaskSpace, RefusesMalformedBounds) {
  using J = nlohmann::ordered_json;
  EXPECT_THROW(TaskSpace::from_json(J::parse(R"({"a": [1]})")), UserError);
  EXPECT_THROW(TaskSpace::from_json(J::parse(R"({"a": [2, 1]})")), UserError);
  EXPECT_THROW(TaskSpace::from_json(J::parse(R"({"a": [0, 1, 0]})")), UserError);
  EXPECT_THROW(TaskSpace::from_json(J::parse(R"({"a": [0, 1, 2.5]})")), UserError);
  EXPECT_THROW(TaskSpace::from_json(J::parse(R"({"a": [[0, 1], [2]]})")), UserError);
  EXPECT_THROW(TaskSpace::from_json(J::parse(R"({"a": ["x", 1]})")), UserError);
  EXPECT_THROW(TaskSpace::from_json(J::parse(R"({})")), UserError);
  EXPECT_THROW(TaskSpace::from_json(J::parse(R"([0, 1])")), UserError);
  try {
    TaskSpace::from_json(J::parse(R"({"height": [3, 0]})"));
    FAIL();
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("height"), std::string::npos);
  }
}

TEST(DimensionShuffle, IsABijectionMappingIntervalKOntoPermutedIntervalK) {
  const DimensionShuffle shuffle({0.f, -3.f}, {3.f, 9.f}, 21);
  std::set<std::vector<int>> seen;
  for (const auto& perm : shuffle.permutations()) {
    std::set<int> values(perm.begin(), perm.end());
    EXPECT_EQ(values.size(), 4u);  // a permutation of 0..3
    seen.insert(perm);
  }
  for (int d = 0; d < 2; ++d) {
    const float lo = d == 0 ? 0.f : -3.f, width = d == 0 ? 0.75f : 3.f;
    for (int k = 0; k < 4; ++k) {
      for (float frac : {0.1f, 0.5f, 0.9f}) {
        Task t = {1.f, 1.f};
        t[d] = lo + (k + frac) * width;
        const Task real = shuffle.to_real(t);
        // Linearly onto interval perm[k], same position inside it.
        const float expected = lo + (shuffle.permutations()[d][k] + frac) * width;
        EXPECT_NEAR(real[d], expected, 1e-5);
        const Task back = shuffle.to_shuffled(real);
        EXPECT_NEAR(back[d], t[d], 1e-5);
      }
    }
  }
  // Some seed moves something (the identity for every seed would make the criterion void).
  bool moved = false;
  for (std::uint64_t seed = 0; seed < 5 && !moved; ++seed) {
    const DimensionShuffle s({0.f}, {1.f}, seed);
    moved = s.permutations()[0] != std::vector<int>{0, 1, 2, 3};
  }
  EXPECT_TRUE(moved);
}

TEST(RewardScaling, InterpolatesAndClips) {
  EXPECT_DOUBLE_EQ(scale_return(-150, -150, 350), 0.0);
  EXPECT_DOUBLE_EQ(scale_return(100, -150, 350), 0.5);
  EXPECT_DOUBLE_EQ(scale_return(350, -150, 350), 1.0);
  EXPECT_DOUBLE_EQ(scale_return(1000, -150, 350), 1.0);
  EXPECT_DOUBLE_EQ(scale_return(-1000, -150, 350), 0.0);
}

TEST(TestSet, StumpTracksDefaultIsTheGrid) {
  const TaskSpace space = TaskSpace::from_json(
      nlohmann::ordered_json::parse(R"({"stump_height": [0, 3], "obstacle_spacing": [0, 6]})"));
  const std::vector<Task> set = default_test_set(space, 100);
  ASSERT_EQ(set.size(), 100u);
  std::set<float> heights, spacings;
  for (const Task& t : set) {
    heights.insert(t[0]);
    spacings.insert(t[1]);
  }
  EXPECT_EQ(heights.size(), 10u);
  EXPECT_EQ(spacings.size(), 10u);
  EXPECT_FLOAT_EQ(*heights.begin(), 0.f);
  EXPECT_FLOAT_EQ(*heights.rbegin(), 3.f);
  EXPECT_FLOAT_EQ(*spacings.rbegin(), 6.f);
  EXPECT_NEAR(*std::next(spacings.begin()), 6.0 / 9, 1e-6);
}

TEST(TestSet, OtherSpacesGetTheSameUniformSetEveryRun) {
  const TaskSpace space = parkour_like();
  const std::vector<Task> a = default_test_set(space, 50), b = default_test_set(space, 50);
  ASSERT_EQ(a.size(), 50u);
  EXPECT_EQ(a, b);
  for (const Task& t : a)
    for (int d = 0; d < space.dims(); ++d) {
      EXPECT_GE(t[d], space.mins()[d]);
      EXPECT_LE(t[d], space.maxs()[d]);
    }
}

TEST(TestSet, ReadsTheShippedStumpTracksSet) {
  const TaskSpace space = TaskSpace::from_json(
      nlohmann::ordered_json::parse(R"({"obstacle_spacing": [0, 6], "stump_height": [0, 3]})"));
  const std::vector<Task> set = read_test_set_csv(kStumpsSet, space);
  ASSERT_EQ(set.size(), 100u);
  // Columns follow the space's order, not the file's: the first row is (0.0, 3.333).
  EXPECT_NEAR(set[0][0], 3.3333, 1e-3);
  EXPECT_FLOAT_EQ(set[0][1], 0.f);
  const TaskSpace other = TaskSpace::from_json(nlohmann::ordered_json::parse(R"({"x": [0, 6]})"));
  EXPECT_THROW(read_test_set_csv(kStumpsSet, other), UserError);
  EXPECT_THROW(read_test_set_csv("/nonexistent/set.csv", space), UserError);
}

TEST(TeacherController, BooksTasksReturnsAndFeedsTheTeacherRawScaledReturns) {
  const TaskSpace space = TaskSpace::from_json(
      nlohmann::ordered_json::parse(R"({"stump_height": [0, 3], "obstacle_spacing": [0, 6]})"));
  auto teacher = std::make_unique<ScriptedTeacher>(space.mins(), space.maxs(), Task{0.2f, 5.9f});
  ScriptedTeacher* t = teacher.get();
  TeacherController c(std::move(teacher), space,
                      {.seed = 21,
                       .shuffle_dimensions = true,
                       .scale_reward = true,
                       .reward_lb = -150,
                       .reward_ub = 350,
                       .test_set = default_test_set(space, 100),
                       .keep_periodical_task_samples = 3,
                       .periodical_samples = 5});
  const SampledTask s = c.sample_train_task();
  EXPECT_EQ(s.raw, (Task{0.2f, 5.9f}));
  const DimensionShuffle shuffle(space.mins(), space.maxs(), 21);
  EXPECT_EQ(s.real, shuffle.to_real(s.raw));
  for (int i = 0; i < 7; ++i) c.record_train_step({0}, {0}, 1, {0}, false);
  EXPECT_EQ(t->steps, 7);
  EXPECT_EQ(c.env_steps(), 7);
  c.record_train_episode(s.raw, 100, 7, false);
  ASSERT_EQ(t->tasks.size(), 1u);
  EXPECT_EQ(t->tasks[0], s.raw);         // the teacher hears its own vector
  EXPECT_DOUBLE_EQ(t->returns[0], 0.5);  // scaled
  // Two snapshots (steps 3 and 6) of 5 tasks each, in real space.
  const std::vector<PeriodicalRecord> p = c.take_periodical();
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p[1].env_steps, 6);
  ASSERT_EQ(p[0].tasks.size(), 5u);
  EXPECT_EQ(p[0].tasks[0], s.real);
  const std::vector<EpisodeRecord> e = c.take_episodes();
  ASSERT_EQ(e.size(), 1u);
  EXPECT_EQ(e[0].task, s.real);
  EXPECT_DOUBLE_EQ(e[0].ret, 100);
  EXPECT_DOUBLE_EQ(e[0].norm_ret, 0.5);
  EXPECT_EQ(e[0].env_steps, 7);
  EXPECT_TRUE(c.take_episodes().empty());

  // Test tasks in order, wrapping around.
  for (int i = 0; i < 101; ++i) {
    const Task task = c.next_test_task();
    EXPECT_EQ(task, c.test_set()[i % 100]);
    c.record_test_episode(i, 10);
  }
  const nlohmann::json books = c.books();
  EXPECT_EQ(books["env_params_train"].size(), 1u);
  EXPECT_DOUBLE_EQ(books["env_train_rewards"][0].get<double>(), 100);
  EXPECT_DOUBLE_EQ(books["env_train_norm_rewards"][0].get<double>(), 0.5);
  EXPECT_EQ(books["env_train_len"][0].get<int>(), 7);
  EXPECT_EQ(books["env_params_test"].size(), 101u);
  EXPECT_EQ(books["env_test_rewards"].size(), 101u);
  EXPECT_EQ(books["periodical_samples"].size(), 2u);
}

TEST(TeacherController, ReplaysBookedEpisodesIntoTheTeacher) {
  const TaskSpace space =
      TaskSpace::from_json(nlohmann::ordered_json::parse(R"({"a": [0, 1], "b": [0, 1]})"));
  auto teacher = std::make_unique<ScriptedTeacher>(space.mins(), space.maxs(), Task{0.5f, 0.5f});
  ScriptedTeacher* t = teacher.get();
  TeacherController c(std::move(teacher), space,
                      {.seed = 3, .shuffle_dimensions = true, .test_set = {{0.f, 0.f}}});
  c.replay_train_episode({0.1f, 0.9f}, 250, 100, true, 100);
  EXPECT_EQ(t->samples, 1);  // its generator advanced as in the original run
  ASSERT_EQ(t->tasks.size(), 1u);
  const DimensionShuffle shuffle(space.mins(), space.maxs(), 3);
  EXPECT_NEAR(t->tasks[0][0], shuffle.to_shuffled({0.1f, 0.9f})[0], 1e-6);
  EXPECT_DOUBLE_EQ(t->returns[0], 250);  // not scaled
  EXPECT_TRUE(t->successes[0]);
  EXPECT_EQ(c.episodes(), 1);
  EXPECT_EQ(c.env_steps(), 100);
  EXPECT_TRUE(c.take_episodes().empty());  // already written by the earlier run
}

TEST(TeacherController, RefusesMismatches) {
  const TaskSpace space =
      TaskSpace::from_json(nlohmann::ordered_json::parse(R"({"a": [0, 1], "b": [0, 1]})"));
  auto make = [&](int dims) {
    return std::make_unique<ScriptedTeacher>(std::vector<float>(dims, 0.f),
                                             std::vector<float>(dims, 1.f), Task(dims, 0.f));
  };
  EXPECT_THROW(TeacherController(make(3), space, {.test_set = {{0.f, 0.f}}}), UserError);
  EXPECT_THROW(TeacherController(make(2), space, {.test_set = {}}), UserError);
  EXPECT_THROW(TeacherController(make(2), space, {.test_set = {{0.f}}}), UserError);
  EXPECT_THROW(
      TeacherController(make(2), space, {.reward_lb = 1, .reward_ub = 1, .test_set = {{0.f, 0.f}}}),
      UserError);
}

}  // namespace
}  // namespace cradle::teach

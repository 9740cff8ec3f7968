// The teacher registry: names, kwargs by the reference's names, expert-knowledge rules.
#include "teach/registry.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/error.h"

namespace cradle::teach {
namespace {

// The UserError message of `make`, or "" when it does not throw.
template <typename F>
std::string error_of(F make) {
  try {
    make();
  } catch (const UserError& e) {
    return e.what();
  }
  return "";
}

TeacherSetup setup_of(const std::string& name, ExpertKnowledge ek = ExpertKnowledge::low) {
  TeacherSetup s;
  s.name = name;
  s.mins = {0.f, 0.f};
  s.maxs = {3.f, 6.f};
  s.seed = 7;
  s.expert_knowledge = ek;
  return s;
}

TEST(Registry, ParsesExpertKnowledge) {
  EXPECT_EQ(parse_expert_knowledge("none"), ExpertKnowledge::none);
  EXPECT_EQ(parse_expert_knowledge("no"), ExpertKnowledge::none);
  EXPECT_EQ(parse_expert_knowledge("low"), ExpertKnowledge::low);
  EXPECT_EQ(parse_expert_knowledge("high"), ExpertKnowledge::high);
  EXPECT_STREQ(expert_knowledge_name(ExpertKnowledge::high), "high");
  EXPECT_NE(error_of([] { parse_expert_knowledge("original"); }).find("expected none"),
            std::string::npos);
}

TEST(Registry, ListsTheEightTeachersAndRefusesOthers) {
  EXPECT_EQ(teacher_names(),
            (std::vector<std::string>{"Random", "ADR", "ALP-GMM", "Covar-GMM", "RIAC", "Self-Paced",
                                      "GoalGAN", "Setter-Solver"}));
  const std::string message = error_of([] { make_teacher(setup_of("alp_gmm")); });
  EXPECT_NE(message.find("unknown teacher 'alp_gmm'"), std::string::npos) << message;
  EXPECT_NE(message.find("Setter-Solver"), std::string::npos) << message;
}

TEST(Registry, EveryTeacherSamplesInsideTheBox) {
  for (const auto& name : teacher_names()) {
    std::unique_ptr<Teacher> t;
    try {
      t = make_teacher(setup_of(name));
    } catch (const UserError& e) {
      ASSERT_NE(std::string(e.what()).find("not implemented yet"), std::string::npos) << e.what();
      continue;
    }
    for (int n = 0; n < 50; ++n) {
      const Task task = t->sample_task();
      ASSERT_EQ(task.size(), 2u) << name;
      EXPECT_TRUE(task[0] >= 0.f && task[0] <= 3.f && task[1] >= 0.f && task[1] <= 6.f) << name;
      t->episodic_update(task, task[0] < 1.f ? 200.0 : 0.0, task[0] < 1.f);
    }
    EXPECT_TRUE(t->dump().is_object()) << name;
  }
}

TEST(Registry, RefusesWhatTheReferenceRefusesWithoutExpertKnowledge) {
  for (const char* name : {"ADR", "GoalGAN", "Setter-Solver"}) {
    const std::string message =
        error_of([&] { make_teacher(setup_of(name, ExpertKnowledge::none)); });
    EXPECT_NE(message.find("expert knowledge none"), std::string::npos) << name << ": " << message;
  }
  for (const char* name : {"Random", "ALP-GMM", "RIAC"})
    EXPECT_NO_THROW(make_teacher(setup_of(name, ExpertKnowledge::none))) << name;
}

TEST(Registry, ReadsKwargsByTheReferenceNamesAndRefusesUnknownOrMistyped) {
  auto s = setup_of("ALP-GMM");
  s.params = {{"fit_rate", 20}, {"potential_ks", {2, 3}}, {"random_task_ratio", 0.0}};
  auto t = make_teacher(s);
  for (int n = 0; n < 20; ++n) t->episodic_update(t->sample_task(), 0.0, false);
  EXPECT_EQ(t->dump().at("fits").get<int>(), 1);  // fit_rate 20 took effect

  s.params = {{"fit_rat", 20}};
  std::string message = error_of([&] { make_teacher(s); });
  EXPECT_NE(message.find("unknown parameter 'fit_rat'"), std::string::npos) << message;
  EXPECT_NE(message.find("fit_rate"), std::string::npos) << message;

  s.params = {{"fit_rate", "many"}};
  message = error_of([&] { make_teacher(s); });
  EXPECT_NE(message.find("'fit_rate' is \"many\"; expected an integer"), std::string::npos)
      << message;

  s.params = {{"nb_em_init", 3}};
  EXPECT_NE(error_of([&] { make_teacher(s); }).find("not supported"), std::string::npos);

  s.name = "Random";
  s.params = {{"fit_rate", 20}};
  EXPECT_NE(error_of([&] { make_teacher(s); }).find("expected one of: (none)"), std::string::npos);
}

TEST(Registry, HighExpertKnowledgeStartsFromTheEasyRegion) {
  const DiagGaussian easy{{0.f, 6.f}, {0.09f, 0.36f}};  // Stump Tracks: no stumps, max spacing
  // ADR: the box is the single point at the easy region's mean.
  auto adr = setup_of("ADR", ExpertKnowledge::high);
  adr.initial_dist = easy;
  adr.params = {{"boundary_sampling_p", 0.0}};
  EXPECT_EQ(make_teacher(adr)->sample_task(), (Task{0.f, 6.f}));
  // At low, the initial point is random instead.
  adr.expert_knowledge = ExpertKnowledge::low;
  EXPECT_NE(make_teacher(adr)->sample_task(), (Task{0.f, 6.f}));
  // ALP-GMM bootstraps in the easy region at high (within 5 std), uniformly at low.
  auto gmm = setup_of("ALP-GMM", ExpertKnowledge::high);
  gmm.initial_dist = easy;
  auto high = make_teacher(gmm);
  gmm.expert_knowledge = ExpertKnowledge::low;
  auto low = make_teacher(gmm);
  int high_near = 0, low_near = 0;
  for (int n = 0; n < 100; ++n) {
    const Task h = high->sample_task(), l = low->sample_task();
    high_near += h[0] < 1.5f && h[1] > 3.f;
    low_near += l[0] < 1.5f && l[1] > 3.f;
  }
  EXPECT_EQ(high_near, 100);
  EXPECT_LT(low_near, 50);
  // A wrongly sized easy region is refused with its name.
  gmm.expert_knowledge = ExpertKnowledge::high;
  gmm.initial_dist = DiagGaussian{{0.f}, {1.f}};
  EXPECT_NE(error_of([&] { make_teacher(gmm); }).find("initial_dist"), std::string::npos);
}

TEST(Registry, ScalesAdrThresholdsWithTheReturns) {
  // With returns scaled from [-100, 100], the thresholds 0 and 60 become 0.5 and 0.8: a return of
  // 0.9 expands the box (unscaled, 0.9 would lie between 0 and 60 and change nothing).
  auto s = setup_of("ADR", ExpertKnowledge::high);
  s.initial_dist = DiagGaussian{{1.5f, 3.f}, {0.f, 0.f}};
  s.scale_reward = true;
  s.params = {{"boundary_sampling_p", 1.0}, {"min_reward_thr", 0.0}, {"max_reward_thr", 60.0}};
  auto t = make_teacher(s);
  for (int n = 0; n < 40; ++n) t->episodic_update(t->sample_task(), 0.9, true);
  const auto cur_max = t->dump().at("cur_max").get<std::vector<float>>();
  EXPECT_GT(cur_max[0] + cur_max[1], 1.5f + 3.f);
  s.reward_lb = 5;
  s.reward_ub = 5;
  EXPECT_NE(error_of([&] { make_teacher(s); }).find("reward bounds"), std::string::npos);
}

}  // namespace
}  // namespace cradle::teach

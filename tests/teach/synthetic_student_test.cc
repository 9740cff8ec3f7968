// The synthetic student learns only next to what it knows; ALP-GMM beats Random on it.
#include "teach/synthetic_student.h"

#include <gtest/gtest.h>

#include "core/error.h"
#include "teach/registry.h"

namespace cradle::teach {
namespace {

TEST(SyntheticStudent, LearnsOnlyNextToWhatItKnows) {
  SyntheticStudent s({}, 1);
  EXPECT_DOUBLE_EQ(s.mastered_percent(), 100.0 / 400);  // the corner cell
  // Far from the corner: no progress however long it practises.
  for (int n = 0; n < 50; ++n) EXPECT_NEAR(s.play({0.2f, 0.9f}).first, 0.0, 6.0);
  // Next to the corner: mastered after 9 practice episodes (competence 0.9).
  for (int n = 0; n < 9; ++n) s.play({0.07f, 0.07f});
  EXPECT_DOUBLE_EQ(s.mastered_percent(), 200.0 / 400);
  const auto [ret, success] = s.play({0.07f, 0.07f});
  EXPECT_NEAR(ret, 180.0, 6.0);
  EXPECT_TRUE(success);
  // The unlearnable columns (x >= 0.4) stay at zero even next to mastered cells.
  SyntheticStudent wide({.cells = 2, .learnable_columns = 1}, 2);
  for (int n = 0; n < 20; ++n) wide.play({0.9f, 0.1f});
  EXPECT_DOUBLE_EQ(wide.mastered_percent(), 25.0);
  EXPECT_THROW(SyntheticStudent({.cells = 0}, 0), UserError);
}

TEST(SyntheticStudent, AlpGmmMastersMoreThanRandom) {
  std::vector<double> alp, random;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    TeacherSetup setup{.name = "ALP-GMM", .mins = {0.f, 0.f}, .maxs = {1.f, 1.f}, .seed = seed};
    setup.params = {
        {"fit_rate", 150}, {"potential_ks", {2, 3, 4, 5, 6, 7, 8, 9}}, {"random_task_ratio", 0.05}};
    auto t = make_teacher(setup);
    alp.push_back(run_synthetic_curriculum(*t, 3000, seed));
    setup.name = "Random";
    setup.params = nlohmann::json::object();
    auto r = make_teacher(setup);
    random.push_back(run_synthetic_curriculum(*r, 3000, seed));
  }
  for (int i = 0; i < 3; ++i) EXPECT_GT(alp[i], random[i]) << "seed " << i + 1;
  EXPECT_GT(welch_t(alp, random), 2.0);
}

TEST(SyntheticStudent, WelchT) {
  // Equal spreads 1 and 3 values each: t = (mean diff) / sqrt(1/3 + 1/3).
  EXPECT_NEAR(welch_t({2, 3, 4}, {0, 1, 2}), 2.0 / std::sqrt(2.0 / 3.0), 1e-12);
  EXPECT_THROW(welch_t({1}, {1, 2}), UserError);
}

}  // namespace
}  // namespace cradle::teach

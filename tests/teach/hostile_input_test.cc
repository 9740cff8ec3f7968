// Hostile inputs to every teacher: non-finite or out-of-bound returns, tasks of the wrong size or
// with non-finite coordinates, and a Self-Paced value estimator that misbehaves. Each is a
// one-line UserError, and the teacher goes on working afterwards (no GMM is fitted on garbage).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/error.h"
#include "teach/gmm.h"
#include "teach/registry.h"

namespace cradle::teach {
namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// Small settings so that every teacher fits or trains within a few dozen episodes.
TeacherSetup setup_of(const std::string& name) {
  TeacherSetup s{.name = name, .mins = {0.f, 0.f}, .maxs = {3.f, 6.f}, .seed = 1};
  s.expert_knowledge = ExpertKnowledge::low;
  if (name == "ALP-GMM" || name == "Covar-GMM")
    s.params = {{"fit_rate", 10}, {"potential_ks", {2, 3}}};
  if (name == "RIAC") s.params = {{"max_region_size", 10}};
  if (name == "GoalGAN")
    s.params = {{"update_size", 8}, {"n_rollouts", 1}, {"train_iterations", 2}};
  if (name == "Setter-Solver") s.params = {{"update_frequency", 8}, {"setter_hidden_size", 8}};
  if (name == "Self-Paced") s.params = {{"update_frequency", 10}, {"update_offset", 0}};
  return s;
}

// The UserError message of f, or "" when it does not throw one.
template <typename F>
std::string error_of(F f) {
  try {
    f();
  } catch (const UserError& e) {
    return e.what();
  }
  return "";
}

// Plays n episodes of valid values (Self-Paced through its step hooks) and checks every task.
void play(Teacher& t, int n, const std::string& name) {
  t.set_value_estimator([](const std::vector<std::vector<float>>& states) {
    return std::vector<float>(states.size(), 1.f);
  });
  for (int e = 0; e < n; ++e) {
    const Task task = t.sample_task();
    ASSERT_EQ(task.size(), 2u) << name;
    ASSERT_TRUE(task[0] >= 0.f && task[0] <= 3.f && task[1] >= 0.f && task[1] <= 6.f)
        << name << ": task (" << task[0] << ", " << task[1] << ") outside the box";
    t.record_initial_state(task, task);
    t.step_update(task, {0.f}, 1.0, task, true);
    const bool easy = task[0] < 1.f;
    t.episodic_update(task, easy ? 200.0 : 10.0 * (e % 3), easy);
  }
}

TEST(HostileInput, EveryTeacherRefusesBadEpisodesWithOneLineAndKeepsWorking) {
  const Task good = {1.f, 2.f};
  const float nan_f = std::numeric_limits<float>::quiet_NaN();
  const float inf_f = std::numeric_limits<float>::infinity();
  const std::vector<std::pair<std::string, Task>> bad_tasks = {
      {"empty", {}},         {"short", {1.f}},      {"long", {1.f, 2.f, 3.f}},
      {"nan", {nan_f, 2.f}}, {"inf", {1.f, inf_f}}, {"-inf", {-inf_f, 2.f}},
      {"huge", {1.f, 3e38f}}};
  const std::vector<double> bad_returns = {kNan, kInf, -kInf, 1e170, -1e300, kMaxAbsReturn * 2};
  for (const auto& name : teacher_names()) {
    auto t = make_teacher(setup_of(name));
    // Interleave refusals with valid episodes so that fits and trainings happen in between.
    for (int round = 0; round < 3; ++round) {
      for (const auto& [what, task] : bad_tasks) {
        const std::string message = error_of([&] { t->episodic_update(task, 1.0, false); });
        EXPECT_NE(message.find("task"), std::string::npos) << name << " " << what << ": no error";
        EXPECT_EQ(message.find('\n'), std::string::npos) << name << ": " << message;
      }
      for (double ret : bad_returns) {
        const std::string message = error_of([&] { t->episodic_update(good, ret, true); });
        EXPECT_NE(message.find("return"), std::string::npos) << name << " " << ret << ": no error";
        EXPECT_EQ(message.find('\n'), std::string::npos) << name << ": " << message;
      }
      play(*t, 20, name);
    }
    // The teacher still samples in the box and its book-keeping serialises.
    EXPECT_NO_THROW(t->non_exploratory_task_sampling()) << name;
    const nlohmann::json dump = t->dump();
    EXPECT_NO_THROW((void)dump.dump()) << name;
  }
}

TEST(HostileInput, ReturnsAtTheBoundKeepEveryFitFinite) {
  // Returns of either sign at the documented bound, on GMM teachers that refit every 10 episodes.
  for (const char* name : {"ALP-GMM", "Covar-GMM", "RIAC", "ADR"}) {
    auto t = make_teacher(setup_of(name));
    for (int e = 0; e < 200; ++e) {
      const Task task = t->sample_task();
      ASSERT_TRUE(std::isfinite(task[0]) && std::isfinite(task[1])) << name << " episode " << e;
      ASSERT_TRUE(task[0] >= 0.f && task[0] <= 3.f && task[1] >= 0.f && task[1] <= 6.f) << name;
      const double ret = (e % 3 == 0 ? -1.0 : 1.0) * kMaxAbsReturn * (task[0] / 3.0);
      t->episodic_update(task, ret, false);
    }
    EXPECT_NO_THROW((void)t->dump().dump()) << name;
    if (std::string(name) == "ALP-GMM" || std::string(name) == "Covar-GMM") {
      // Every fit was usable: the bound keeps EM finite, the guard was not needed.
      EXPECT_EQ(t->dump().at("fits").get<int>(), 20) << name;
      EXPECT_EQ(t->dump().at("failed_fits").get<int>(), 0) << name;
      for (int n = 0; n < 100; ++n) {
        const Task task = t->non_exploratory_task_sampling();
        ASSERT_TRUE(task[0] >= 0.f && task[0] <= 3.f && task[1] >= 0.f && task[1] <= 6.f) << name;
      }
    }
  }
}

TEST(HostileInput, StepHooksRefuseBadValues) {
  for (const auto& name : teacher_names()) {
    auto t = make_teacher(setup_of(name));
    std::string message = error_of([&] { t->record_initial_state({1.f}, {0.f}); });
    EXPECT_NE(message.find("task"), std::string::npos) << name << ": no error";
    message = error_of([&] { t->record_initial_state({1.f, 2.f}, {NAN}); });
    EXPECT_NE(message.find("state"), std::string::npos) << name << ": no error";
    message = error_of([&] { t->step_update({0.f}, {0.f}, kNan, {0.f}, false); });
    EXPECT_NE(message.find("reward"), std::string::npos) << name << ": no error";
  }
}

TEST(HostileInput, SelfPacedRefusesAMisbehavingValueEstimator) {
  auto run = [](ValueEstimator estimator) {
    auto t = make_teacher(setup_of("Self-Paced"));
    t->set_value_estimator(std::move(estimator));
    for (int e = 0; e < 10; ++e) {
      const Task task = t->sample_task();
      t->record_initial_state(task, task);
      t->step_update(task, {0.f}, 1.0, task, true);
    }
  };
  using States = std::vector<std::vector<float>>;
  std::string message = error_of([&] { run([](const States&) { return std::vector<float>{}; }); });
  EXPECT_NE(message.find("returned 0 values for 10 states"), std::string::npos) << message;
  message =
      error_of([&] { run([](const States& s) { return std::vector<float>(s.size() + 1, 1.f); }); });
  EXPECT_NE(message.find("returned 11 values for 10 states"), std::string::npos) << message;
  message = error_of([&] {
    run([](const States& s) {
      std::vector<float> v(s.size(), 1.f);
      v[3] = std::numeric_limits<float>::quiet_NaN();
      return v;
    });
  });
  EXPECT_NE(message.find("value 3 is nan"), std::string::npos) << message;
  // An estimator's own exception reaches the caller unchanged.
  EXPECT_THROW(run([](const States&) -> std::vector<float> { throw std::runtime_error("boom"); }),
               std::runtime_error);
  // Without any estimator the first update is an error, not a silent skip.
  message = error_of([&] { run(nullptr); });
  EXPECT_NE(message.find("no value estimator"), std::string::npos) << message;
}

TEST(HostileInput, GmmRefusesNonFinitePointsAndFlagsUnusableMixtures) {
  Rng rng(3);
  Eigen::MatrixXd x = Eigen::MatrixXd::Random(20, 3);
  const Gmm fitted = fit_gmm(x, 2, rng);
  EXPECT_TRUE(usable(fitted));
  x(4, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(error_of([&] { fit_gmm(x, 2, rng); }).find("non-finite"), std::string::npos);
  EXPECT_FALSE(usable(Gmm{}));  // no component: what fit_best_gmm gives when no fit is usable
  Gmm broken = fitted;
  broken.covs[1](0, 0) = -1;  // not positive definite: its draws would be NaN
  EXPECT_FALSE(usable(broken));
  broken = fitted;
  broken.means[0][2] = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(usable(broken));
}

}  // namespace
}  // namespace cradle::teach

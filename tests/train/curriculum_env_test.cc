// CurriculumEnv: the teacher chooses every episode's task before its reset and hears every
// episode's outcome; the wrapped env gets the task as reset options; counts under a vector env.
#include "train/curriculum_env.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <vector>

#include "core/error.h"
#include "learn/vector_env.h"

namespace cradle::train {
namespace {

// An episode lasts round(length) steps and pays `gain` per step; both are reset options.
class Corridor final : public envs::Env {
 public:
  Corridor()
      : obs_space_{{{"observation", Box::unbounded({2}, DType::kFloat64)}}},
        action_space_(Box::uniform({1}, DType::kFloat64, -1, 1)),
        buffers_(obs_space_) {
    success_ = info_.declare("is_success", envs::InfoType::kBool);
  }
  const DictSpace& observation_space() const override { return obs_space_; }
  const Box& action_space() const override { return action_space_; }
  void set_reset_options(const envs::ResetOptions& options) override {
    for (const auto& [name, value] : options) {
      if (name == "length") {
        next_length_ = value;
      } else if (name == "gain") {
        next_gain_ = value;
      } else {
        throw UserError("unknown option " + name);
      }
    }
    ++options_set;
  }
  void reset(std::optional<std::uint64_t>) override {
    length_ = static_cast<int>(std::lround(next_length_));
    gain_ = next_gain_;
    steps_ = 0;
    ++resets;
    write();
  }
  envs::StepResult step(std::span<const double>) override {
    ++steps_;
    write();
    info_.set(success_, steps_ * gain_ > 10);
    return {.reward = gain_, .terminated = false, .truncated = steps_ >= length_};
  }
  const envs::ObservationBuffers& observation() const override { return buffers_; }
  const envs::Info& info() const override { return info_; }
  double score() const override { return 100.0 * steps_; }

  int resets = 0, options_set = 0;
  double gain_ = 0, next_length_ = 1, next_gain_ = 0;

 private:
  void write() {
    buffers_.f64(0)[0] = steps_;
    buffers_.f64(0)[1] = gain_;
  }
  DictSpace obs_space_;
  Box action_space_;
  envs::ObservationBuffers buffers_;
  envs::Info info_;
  int success_ = -1, length_ = 1, steps_ = 0;
};

// Proposes tasks in turn from a list and records what it hears.
class ListTeacher final : public teach::Teacher {
 public:
  explicit ListTeacher(std::vector<teach::Task> tasks)
      : Teacher({1.f, 0.f}, {10.f, 5.f}, 1), tasks_(std::move(tasks)) {}
  teach::Task sample_task() override { return tasks_[samples++ % tasks_.size()]; }
  void record_initial_state(const teach::Task&, const std::vector<float>& s0) override {
    initial_states.push_back(s0);
  }
  void step_update(const std::vector<float>&, const std::vector<float>&, double,
                   const std::vector<float>&, bool) override {
    ++steps;
  }
  void episodic_update(const teach::Task& task, double ret, bool success) override {
    heard.push_back({task, ret, success});
  }
  const char* name() const override { return "List"; }

  struct Heard {
    teach::Task task;
    double ret;
    bool success;
  };
  std::vector<teach::Task> tasks_;
  int samples = 0, steps = 0;
  std::vector<Heard> heard;
  std::vector<std::vector<float>> initial_states;
};

std::shared_ptr<teach::TeacherController> controller_of(std::unique_ptr<ListTeacher> teacher) {
  teach::TaskSpace space = teach::TaskSpace::from_json(
      nlohmann::ordered_json::parse(R"({"length": [1, 10], "gain": [0, 5]})"));
  return std::make_shared<teach::TeacherController>(
      std::move(teacher), std::move(space), teach::ControllerOptions{.test_set = {{1.f, 0.f}}});
}

TEST(CurriculumEnv, AsksBeforeEveryResetAndReportsEveryEpisode) {
  auto teacher = std::make_unique<ListTeacher>(std::vector<teach::Task>{{3.f, 2.f}, {5.f, 4.f}});
  ListTeacher* t = teacher.get();
  auto inner = std::make_unique<Corridor>();
  Corridor* corridor = inner.get();
  CurriculumEnv env(std::move(inner), controller_of(std::move(teacher)), {.success_threshold = 12});
  const std::vector<double> a = {0.5};
  for (int episode = 0; episode < 4; ++episode) {
    env.reset();
    EXPECT_EQ(t->samples, episode + 1);  // asked before the reset
    EXPECT_EQ(corridor->resets, episode + 1);
    EXPECT_EQ(corridor->options_set, episode + 1);
    const double gain = episode % 2 ? 4 : 2;
    EXPECT_EQ(corridor->gain_, gain);
    EXPECT_EQ(env.task().real, (episode % 2 ? teach::Task{5.f, 4.f} : teach::Task{3.f, 2.f}));
    envs::StepResult r;
    int steps = 0;
    do {
      EXPECT_EQ(t->heard.size(), static_cast<std::size_t>(episode));  // not before the end
      r = env.step(a);
      ++steps;
    } while (!r.truncated);
    EXPECT_EQ(steps, episode % 2 ? 5 : 3);
    ASSERT_EQ(t->heard.size(), static_cast<std::size_t>(episode + 1));
    EXPECT_DOUBLE_EQ(t->heard.back().ret, steps * gain);
    EXPECT_EQ(t->heard.back().success, steps * gain > 12);  // 6 fails, 20 succeeds
  }
  EXPECT_EQ(t->steps, 3 + 5 + 3 + 5);
  ASSERT_EQ(t->initial_states.size(), 4u);
  EXPECT_EQ(t->initial_states[1], (std::vector<float>{0.f, 4.f}));
}

TEST(CurriculumEnv, SuccessFromTheEnvFlagWithoutAThreshold) {
  auto teacher = std::make_unique<ListTeacher>(std::vector<teach::Task>{{3.f, 4.f}, {2.f, 1.f}});
  ListTeacher* t = teacher.get();
  CurriculumEnv env(std::make_unique<Corridor>(), controller_of(std::move(teacher)));
  const std::vector<double> a = {0.0};
  for (int episode = 0; episode < 2; ++episode) {
    env.reset();
    while (!env.step(a).truncated) {
    }
  }
  ASSERT_EQ(t->heard.size(), 2u);
  EXPECT_TRUE(t->heard[0].success);   // 12 > 10
  EXPECT_FALSE(t->heard[1].success);  // 2
}

TEST(CurriculumEnv, TheTeacherHearsTheScoreWhenAsked) {
  auto teacher = std::make_unique<ListTeacher>(std::vector<teach::Task>{{3.f, 1.f}});
  ListTeacher* t = teacher.get();
  CurriculumEnv env(std::make_unique<Corridor>(), controller_of(std::move(teacher)),
                    {.success_threshold = 250, .use_score = true});
  env.reset();
  const std::vector<double> a = {0.0};
  while (!env.step(a).truncated) {
  }
  ASSERT_EQ(t->heard.size(), 1u);
  EXPECT_DOUBLE_EQ(t->heard[0].ret, 300);  // the score of 3 steps, not the return 3
  EXPECT_TRUE(t->heard[0].success);
}

TEST(CurriculumEnv, CountsUnderAVectorEnvWithAutoreset) {
  auto teacher = std::make_unique<ListTeacher>(std::vector<teach::Task>{{4.f, 1.f}});
  ListTeacher* t = teacher.get();
  auto controller = controller_of(std::move(teacher));
  std::vector<std::unique_ptr<envs::Env>> list;
  for (int i = 0; i < 3; ++i)
    list.push_back(std::make_unique<CurriculumEnv>(std::make_unique<Corridor>(), controller));
  learn::ThreadedVecEnv vec(std::move(list), 2);
  vec.reset(7);
  EXPECT_EQ(t->samples, 3);
  const std::vector<double> actions(3, 0.0);
  // 4-step episodes and one autoreset step each: 20 vector steps = 4 episodes per env.
  for (int i = 0; i < 20; ++i) vec.step(actions);
  EXPECT_EQ(t->heard.size(), 12u);
  EXPECT_EQ(t->samples, 3 + 12);
  EXPECT_EQ(t->steps, 3 * 16);
  EXPECT_EQ(controller->env_steps(), 48);
  EXPECT_EQ(controller->episodes(), 12);
  for (const auto& h : t->heard) EXPECT_DOUBLE_EQ(h.ret, 4.0);
}

TEST(CurriculumEnv, RefusesATeachersParameterAsAnOption) {
  CurriculumEnv env(
      std::make_unique<Corridor>(),
      controller_of(std::make_unique<ListTeacher>(std::vector<teach::Task>{{4.f, 1.f}})));
  EXPECT_THROW(env.set_reset_options({{"gain", 1}}), UserError);
}

// A student that neither learns nor acts, named `algorithm`; its value is the base Learner's (NaN).
class IdleStudent : public learn::Learner {
 public:
  explicit IdleStudent(std::string_view algorithm) : algorithm_(algorithm) {}
  std::string_view algorithm() const override { return algorithm_; }
  void learn(long, const learn::ProgressFn&) override {}
  long steps() const override { return 0; }
  void save(const std::filesystem::path&) const override {}
  void load(const std::filesystem::path&) override {}
  void act(const envs::ObservationBuffers&, std::span<double>, bool) override {}
  std::string config_text() const override { return ""; }

 private:
  std::string_view algorithm_;
};

// A student whose value of an initial state is level * (1 + gain) (the Corridor's second
// observation), level rising by `rise` at every valuation; NaN stands for no value function.
class ValuedStudent final : public IdleStudent {
 public:
  explicit ValuedStudent(double rise) : IdleStudent("stub"), rise_(rise) {}
  double value(const envs::ObservationBuffers& obs) override {
    ++valued;
    level_ += rise_;
    return level_ * (1.0 + obs.f64(0)[1]);
  }
  int valued = 0;

 private:
  double rise_, level_ = 0;
};

// The KLs to the target SPDL booked at each update, after `steps` Corridor steps under a student.
std::vector<double> spdl_kls(learn::Learner& student, int steps) {
  teach::SelfPacedParams p;
  p.update_frequency = 200;
  p.update_offset = 0;
  p.zeta = 0.5;
  p.initial_dist = teach::DiagGaussian{{2.f, 0.5f}, {0.05f, 0.01f}};  // short, poor episodes
  auto controller = std::make_shared<teach::TeacherController>(
      teach::make_self_paced_teacher({1.f, 0.f}, {10.f, 5.f}, 3, p),
      teach::TaskSpace::from_json(
          nlohmann::ordered_json::parse(R"({"length": [1, 10], "gain": [0, 5]})")),
      teach::ControllerOptions{.test_set = {{1.f, 0.f}}});
  auto corridor = std::make_unique<Corridor>();
  const DictSpace space = corridor->observation_space();
  controller->teacher().set_value_estimator(
      learner_value_estimator([&student]() -> learn::Learner& { return student; }, space));
  CurriculumEnv env(std::move(corridor), controller);
  const std::vector<double> a = {0.0};
  env.reset();
  for (int i = 0; i < steps; ++i) {
    const envs::StepResult r = env.step(a);
    if (r.terminated || r.truncated) env.reset();
  }
  std::vector<double> kls;
  const nlohmann::json dump = controller->teacher_dump();
  for (const auto& h : dump.at("history")) kls.push_back(h.at("kl"));
  return kls;
}

TEST(CurriculumEnv, SelfPacedMovesTowardTheTargetAsTheStudentsValueRises) {
  // A student whose values rise: SPDL's distribution approaches the target (the whole box).
  ValuedStudent rising(0.01);
  const std::vector<double> moved = spdl_kls(rising, 2000);
  ASSERT_EQ(moved.size(), 11u);   // the start and 10 updates
  EXPECT_GT(rising.valued, 100);  // the initial states of the episodes were valued
  // KL to the target shrinks update after update (6.3 -> 4.2 here; max_kl bounds each step).
  int closer = 0;
  for (std::size_t i = 1; i < moved.size(); ++i) closer += moved[i] < moved[i - 1];
  EXPECT_GE(closer, 8);
  EXPECT_LT(moved.back(), 0.75 * moved.front());
  // A student that values nothing: no performance, no pull toward the target.
  ValuedStudent flat(0.0);
  const std::vector<double> still = spdl_kls(flat, 2000);
  ASSERT_EQ(still.size(), 11u);
  EXPECT_NEAR(still.back(), still.front(), 1e-6 * still.front());
}

TEST(CurriculumEnv, SelfPacedRefusesAStudentWithoutValue) {
  // The base Learner::value is NaN: the first update says which students can serve.
  IdleStudent student("td3");
  try {
    spdl_kls(student, 400);
    FAIL() << "no error";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("not td3"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace cradle::train

// Task-space files of `cradle train --task-space`: parsed in order, one-line errors otherwise; the
// shipped example builds a working controller.
#include "train/task_space.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "core/error.h"

namespace cradle::train {
namespace {

TEST(TaskSpaceFile, ParsesTeacherBoundsAndOptions) {
  const CurriculumSpec spec = parse_task_space(R"(
teacher: RIAC
params:
  start_posture_range: [0, 1]
  gains: [0, 2, 3]
  box: [[0, 1], [5, 6]]
teacher_params: {max_region_size: 30}
expert_knowledge: low
success_threshold: 12.5
reward_bounds: [-10, 40]
scale_reward: true
)",
                                               "test.yml");
  EXPECT_EQ(spec.teacher, "RIAC");
  ASSERT_TRUE(spec.space);
  EXPECT_EQ(spec.space->dim_names(),
            (std::vector<std::string>{"start_posture_range", "gains_0", "gains_1", "gains_2",
                                      "box_0", "box_1"}));
  EXPECT_EQ(spec.space->maxs()[5], 6.f);
  EXPECT_EQ(spec.teacher_params["max_region_size"], 30);
  EXPECT_EQ(spec.expert_knowledge, "low");
  EXPECT_DOUBLE_EQ(spec.env_options.success_threshold, 12.5);
  EXPECT_DOUBLE_EQ(spec.reward_lb, -10);
  EXPECT_TRUE(spec.scale_reward);
  auto controller = make_controller(spec, 5);
  const teach::SampledTask t = controller->sample_train_task();
  ASSERT_EQ(t.real.size(), 6u);
  EXPECT_GE(t.real[4], 0.f);
  EXPECT_LE(t.real[5], 6.f);
}

TEST(TaskSpaceFile, BadFilesAreOneLineErrors) {
  const char* bad[] = {
      "params: {a: [0, 1]}",                                // no teacher
      "teacher: Random",                                    // no params
      "teacher: Random\nparams: {a: [1, 0]}",               // min > max
      "teacher: Random\nparams: {a: [0, 1]}\ncolour: red",  // unknown key
      "teacher: Random\nparams: {a: [0, 1]}\nexpert_knowledge: lots",
      "teacher: Random\nparams: {a: [0, 1]}\nreward_bounds: [1, 1]",
      "teacher: Random\nparams: {a: [0, 1]}\nsuccess_threshold: high",
      "teacher: [Random]\nparams: {a: [0, 1]}",
      "teacher: Random\nparams: {a: [0, 1",  // not YAML
  };
  for (const char* text : bad) {
    try {
      parse_task_space(text, "bad.yml");
      ADD_FAILURE() << text;
    } catch (const UserError& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
      EXPECT_EQ(message.rfind("bad.yml", 0), 0u) << message;
    }
  }
  const CurriculumSpec unknown = parse_task_space("teacher: Nope\nparams: {a: [0, 1]}", "t.yml");
  EXPECT_THROW(make_controller(unknown, 0), UserError);
  EXPECT_THROW(load_task_space("/nonexistent/space.yml"), UserError);
}

TEST(TaskSpaceFile, ShippedBabyBenchExampleLoads) {
  const CurriculumSpec spec = load_task_space(std::filesystem::path(CRADLE_SOURCE_DIR) /
                                              "configs/curricula/babybench_posture.yml");
  EXPECT_EQ(spec.teacher, "ALP-GMM");
  EXPECT_EQ(spec.space->dim_names(), std::vector<std::string>{"start_posture_range"});
  EXPECT_TRUE(std::isnan(spec.env_options.success_threshold));
  EXPECT_NO_THROW(make_controller(spec, 1));
}

}  // namespace
}  // namespace cradle::train

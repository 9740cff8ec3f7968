// Task-space files of `cradle train --task-space`: parsed in order, one-line errors otherwise; the
// shipped example builds a working controller.
#include "train/task_space.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <nlohmann/json.hpp>

#include "core/error.h"
#include "envs/babybench.h"
#include "envs/mimo/sample_env.h"
#include "fixture.h"
#include "train/families.h"
#include "train/trainer.h"

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
outcome: score
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
  EXPECT_TRUE(spec.env_options.use_score);
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
      "teacher: Random\nparams: {a: [0, 1]}\noutcome: reward",
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

// Without a file a teacher sets every task parameter the env declares, with its family's facts.
TEST(EnvCurriculum, EveryDeclaredParameterWithTheFamilysFacts) {
  // TeachMyAgent: the benchmark's space, return bounds and easy corner (as `cradle tma run`).
  const CurriculumSpec stumps = env_curriculum(envs::env_spec("tma/stump-tracks:spider"));
  EXPECT_EQ(stumps.space->dim_names(),
            (std::vector<std::string>{"stump_height", "obstacle_spacing"}));
  EXPECT_EQ(stumps.space->maxs(), (std::vector<float>{3, 6}));
  EXPECT_EQ(stumps.reward_lb, -150);
  EXPECT_EQ(stumps.reward_ub, 350);
  EXPECT_EQ(stumps.expert_knowledge, "high");
  ASSERT_TRUE(stumps.initial_dist);
  EXPECT_EQ(stumps.initial_dist->mean, (std::vector<float>{0, 6}));
  const CurriculumSpec parkour = env_curriculum(envs::env_spec("tma/parkour:fish"));
  EXPECT_EQ(parkour.space->dims(), 8);
  EXPECT_EQ(parkour.reward_ub, 360);
  EXPECT_FALSE(parkour.initial_dist);
  // SaMI: the hidden parameters in the split's ranges; the teacher hears the return.
  const envs::EnvSpec cheetah = envs::env_spec("sami/HalfCheetah:train");
  const CurriculumSpec sami = env_curriculum(cheetah);
  EXPECT_EQ(sami.space->dim_names(), (std::vector<std::string>{"mass", "damping"}));
  EXPECT_EQ(sami.space->mins()[0], static_cast<float>(cheetah.parameters[0].low));
  EXPECT_EQ(sami.space->maxs()[1], static_cast<float>(cheetah.parameters[1].high));
  EXPECT_FALSE(sami.env_options.use_score);
  EXPECT_EQ(sami.expert_knowledge, "none");
  // BabyBench's reward is 0: its teacher hears the behaviour score.
  EXPECT_TRUE(env_curriculum(envs::env_spec("babybench/handregard")).env_options.use_score);
  // An env without task parameters is a one-line error naming it.
  try {
    (void)env_curriculum(envs::env_spec("mimo/standup"));
    FAIL() << "mimo/standup has no task parameters";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("mimo/standup has no task parameters"), std::string::npos)
        << e.what();
  }
}

// Every family of the env registry has its entry (the run asks it for every env id), each with a
// curriculum, and only SaMI's presets: its learners store whole episodes (horizon = the episode).
TEST(Families, EveryRegisteredFamilyHasItsFacts) {
  for (const envs::EnvSpec& spec : envs::env_specs()) {
    const Family& f = family(spec.family);
    EXPECT_NE(f.curriculum, nullptr) << spec.id;
    EXPECT_EQ(f.presets != nullptr, spec.family == "sami") << spec.id;
    if (!spec.parameters.empty()) {
      EXPECT_TRUE(env_curriculum(spec).space) << spec.id;
    }
  }
  const envs::EnvSpec panda = envs::env_spec("sami/PandaPush:train");
  const auto presets = family("sami").presets(panda, "saccm");
  EXPECT_EQ(presets.at("horizon"), std::to_string(panda.max_episode_steps));
  EXPECT_EQ(presets.at("batch_size"), "256");
  EXPECT_TRUE(family("sami").presets(panda, "sac").empty());  // not one of SaMI's learners
  try {
    (void)family("atari");
    FAIL() << "atari is no family";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("(babybench, mimo, tma, sami)"), std::string::npos)
        << e.what();
  }
}

// Checkpoints written inside the reports (`cradle illustrate`'s) are for runs by id: a BabyBench
// config's checkpoint ends its training log's episodes, so its run is refused before anything is
// written.
TEST(TrainOptionsCheck, CheckpointsInsideReportsAreForRunsById) {
  const std::filesystem::path dir = test::fresh_dir("checkpoints_in_reports");
  Config config = test::reference_config("config_selftouch.yml");
  config.save_dir = (dir / "run").string();
  TrainOptions o{.steps = 64, .envs = 1, .eval_episodes = 0, .progress_bar = false};
  o.checkpoints_split_learning = false;
  try {
    train(config, o);
    FAIL() << "a BabyBench run with checkpoints inside the reports";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("for runs by env id"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "run"));
}

TEST(TaskSpaceFile, ShippedBabyBenchExampleLoads) {
  const CurriculumSpec spec = load_task_space(std::filesystem::path(CRADLE_SOURCE_DIR) /
                                              "configs/curricula/babybench_posture.yml");
  EXPECT_EQ(spec.teacher, "ALP-GMM");
  EXPECT_EQ(spec.space->dim_names(), std::vector<std::string>{"start_posture_range"});
  EXPECT_TRUE(std::isnan(spec.env_options.success_threshold));
  EXPECT_NO_THROW(make_controller(spec, 1));
}

TEST(TaskSpaceFile, ATeacherOfTheRunsOwnNeedsNoTeacherKey) {
  EXPECT_THROW(parse_task_space("params: {a: [0, 1]}", "t.yml"), UserError);
  const CurriculumSpec spec =
      parse_task_space("params: {a: [0, 1], b: [2, 3]}", "t.yml", /*need_teacher=*/false);
  EXPECT_TRUE(spec.teacher.empty());
  auto controller = make_controller(spec, teach::make_random_teacher({0, 2}, {1, 3}, 4), 4);
  const teach::SampledTask t = controller->sample_train_task();
  ASSERT_EQ(t.real.size(), 2u);
  EXPECT_GE(t.real[1], 2.f);
  // A teacher of another dimension, or none, is refused.
  EXPECT_THROW(make_controller(spec, teach::make_random_teacher({0}, {1}, 4), 4), UserError);
  EXPECT_THROW(make_controller(spec, nullptr, 4), UserError);
}

// Hands out task k = (k % 24 / 8, k / 24 / 8) and records what it hears.
class Scripted final : public teach::Teacher {
 public:
  struct Log {
    std::mutex mutex;
    std::vector<teach::Task> handed, updated;
    std::vector<double> returns;
    std::uint64_t seed = 0;
  };
  Scripted(const teach::TaskSpace& space, std::uint64_t seed, std::shared_ptr<Log> log)
      : Teacher(space.mins(), space.maxs(), seed), log_(std::move(log)) {
    log_->seed = seed;
  }
  teach::Task sample_task() override {
    std::lock_guard lock(log_->mutex);
    const int k = static_cast<int>(log_->handed.size());
    log_->handed.push_back({(k % 24) * 0.125f, (k / 24) * 0.125f});
    return log_->handed.back();
  }
  void episodic_update(const teach::Task& task, double ret, bool) override {
    std::lock_guard lock(log_->mutex);
    log_->updated.push_back(task);
    log_->returns.push_back(ret);
  }
  const char* name() const override { return "Scripted"; }

 private:
  std::shared_ptr<Log> log_;
};

TEST(CurriculumRun, ATeacherObjectDrivesARunInsteadOfTheFilesTeacher) {
  const std::filesystem::path dir = test::fresh_dir("curriculum_teacher_object");
  std::ofstream(dir / "space.yml") << "params:\n  stump_height: [0, 3]\n"
                                   << "  obstacle_spacing: [0, 6]\n";
  Config config;
  config.save_dir = (dir / "run").string();
  TrainOptions o{.env = "tma/stump-tracks:old_classic_bipedal",
                 .algorithm = "ppo",
                 .intrinsic = "",
                 .steps = 2048,
                 .envs = 2,
                 .seed = 7};
  o.progress_bar = false;
  o.hyperparameters = {{"n_steps", "64"}, {"batch_size", "64"}, {"n_epochs", "1"}};
  o.task_space = (dir / "space.yml").string();
  auto log = std::make_shared<Scripted::Log>();
  o.teacher_factory = [log](const teach::TaskSpace& space, std::uint64_t seed) {
    return std::make_unique<Scripted>(space, seed, log);
  };
  // A name and an object at once are refused.
  TrainOptions both = o;
  both.teacher = "Random";
  EXPECT_THROW(train(config, both), UserError);
  train(config, o);
  EXPECT_EQ(log->seed, 7u);
  // teacher.jsonl books the episodes in the order the teacher heard them.
  std::ifstream in(dir / "run" / "logs" / "teacher.jsonl");
  std::vector<teach::Task> booked;
  nlohmann::json last;
  for (std::string line; std::getline(in, line);) {
    last = nlohmann::json::parse(line);
    if (last["kind"] == "train") booked.push_back(last["task"].get<teach::Task>());
  }
  ASSERT_FALSE(booked.empty());
  EXPECT_EQ(booked, log->updated);
  EXPECT_LE(log->handed.size() - booked.size(), 2u);  // the episodes the run's end cut short
  EXPECT_EQ(last["teacher"]["teacher"], "Scripted");
  std::filesystem::remove_all(dir);
}

// A shipped task-space file's spec and a controller seeded 3.
std::pair<CurriculumSpec, std::shared_ptr<teach::TeacherController>> shipped(const char* name) {
  CurriculumSpec spec =
      load_task_space(std::filesystem::path(CRADLE_SOURCE_DIR) / "configs/curricula" / name);
  auto controller = make_controller(spec, 3);
  return {std::move(spec), std::move(controller)};
}

TEST(TaskSpaceFile, ReachFilePlacesTheBallWhereTheTeacherSays) {
  auto [spec, controller] = shipped("mimo_reach.yml");
  EXPECT_EQ(spec.space->dim_names(),
            (std::vector<std::string>{"target_dx", "target_dy", "target_dz"}));
  auto inner = envs::make_sample_env("MIMoReach-v0", {.vision_resolution = 16, .render_size = 16});
  const envs::MimoEnv* reach = inner.get();
  const int ball = mj_name2id(reach->model(), mjOBJ_BODY, "target");
  CurriculumEnv env(std::move(inner), controller, spec.env_options);
  const double xml[3] = {0.3, -0.05, 0.7};
  for (int episode = 0; episode < 3; ++episode) {
    env.reset();
    const teach::Task& task = env.task().real;
    for (int i = 0; i < 3; ++i) {
      EXPECT_GE(task[i], spec.space->mins()[i]);
      EXPECT_LE(task[i], spec.space->maxs()[i]);
      EXPECT_NEAR(reach->data()->xpos[3 * ball + i], xml[i] + task[i], 1e-9);
    }
  }
  // Options outside their range or unknown are one-line errors naming what is expected.
  auto bare = envs::make_sample_env("MIMoReach-v0", {.vision_resolution = 16, .render_size = 16});
  EXPECT_THROW(bare->set_reset_options({{"target_dx", 0.5}}), UserError);
  try {
    bare->set_reset_options({{"ball_speed", 1}});
    FAIL() << "no error";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("expected target_dx, target_dy, target_dz"),
              std::string::npos)
        << e.what();
  }
}

TEST(TaskSpaceFile, CatchFileSetsDropHeightSpeedAndRadius) {
  auto [spec, controller] = shipped("mimo_catch.yml");
  EXPECT_EQ(spec.space->dim_names(),
            (std::vector<std::string>{"ball_dz", "ball_speed", "ball_radius"}));
  auto inner = envs::make_sample_env("MIMoCatch-v0", {.vision_resolution = 16, .render_size = 16});
  const envs::MimoEnv* c = inner.get();
  const int ball = mj_name2id(c->model(), mjOBJ_BODY, "target");
  const int geom = mj_name2id(c->model(), mjOBJ_GEOM, "target");
  const int dof = c->model()->jnt_dofadr[mj_name2id(c->model(), mjOBJ_JOINT, "target_joint")];
  CurriculumEnv env(std::move(inner), controller, spec.env_options);
  for (int episode = 0; episode < 3; ++episode) {
    env.reset();
    const teach::Task& task = env.task().real;
    // The ball hovers at its drop height through the settling, then leaves at the set speed.
    EXPECT_NEAR(c->data()->xpos[3 * ball + 2], 0.8 + task[0], 1e-9);
    EXPECT_NEAR(c->data()->qvel[dof + 2], -task[1], 1e-9);
    EXPECT_NEAR(c->model()->geom_size[3 * geom], task[2], 1e-7);
    // Released, it falls.
    const double z0 = c->data()->xpos[3 * ball + 2];
    env.step(std::vector<double>(c->action_space().size(), 0.0));
    EXPECT_LT(c->data()->xpos[3 * ball + 2], z0);
  }
}

TEST(TaskSpaceFile, CubesFileMovesTheStackAwayFromMimo) {
  auto [spec, controller] = shipped("babybench_cubes.yml");
  EXPECT_EQ(spec.space->dim_names(), std::vector<std::string>{"cube_distance"});
  Config config =
      load_config(std::filesystem::path(CRADLE_SOURCE_DIR) / "configs/config_handregard.yml");
  config.vision_active = false;  // the cubes are what matters here
  auto inner = std::make_unique<envs::BabyBenchEnv>(envs::make_assets(config));
  const envs::BabyBenchEnv* baby = inner.get();
  const mjModel* m = baby->model();
  const int root = mj_name2id(m, mjOBJ_BODY, "mimo_location");
  const int red = mj_name2id(m, mjOBJ_BODY, "red_cube"),
            blue = mj_name2id(m, mjOBJ_BODY, "blue_cube");
  CurriculumEnv env(std::move(inner), controller, spec.env_options);
  auto horizontal = [&](int body) {
    const double* p = baby->data()->xpos + 3 * body;
    const double* r = baby->data()->xpos + 3 * root;
    return std::hypot(p[0] - r[0], p[1] - r[1]);
  };
  for (int episode = 0; episode < 3; ++episode) {
    env.reset();
    const double want = env.task().real[0];
    EXPECT_NEAR(horizontal(red), want, 0.005);
    // The stack moved as one: the blue cube keeps its place beside the red one.
    const double* r = baby->data()->xpos + 3 * red;
    const double* b = baby->data()->xpos + 3 * blue;
    EXPECT_NEAR(std::hypot(b[0] - r[0], b[1] - r[1]), std::hypot(0.01, 0.0), 0.01);
  }
  // Another scene has no cubes: a one-line error.
  envs::BabyBenchEnv crib(envs::make_assets(
      load_config(std::filesystem::path(CRADLE_SOURCE_DIR) / "configs/config_selftouch.yml")));
  EXPECT_THROW(crib.set_reset_options({{"cube_distance", 0.3}}), UserError);
}

// A resumed run's teacher book: every line checked before the teacher hears any; a damaged line
// is one line naming the file, the line and the key.
TEST(TeacherBook, ReplaysGoodBooksAndRefusesDamagedLinesWhole) {
  const CurriculumSpec spec =
      parse_task_space("teacher: Random\nparams:\n  a: [0, 1]\n  b: [0, 2]\n", "book.yml");
  const std::filesystem::path file =
      std::filesystem::temp_directory_path() / "cradle_teacher_book.jsonl";
  const std::string good =
      R"({"kind":"train","episode":0,"env_steps":10,"task":[0.5,1],"return":3,"length":10,)"
      R"("success":false})"
      "\n"
      R"({"kind":"dump","env_steps":10,"teacher":{}})"
      "\n"
      R"({"kind":"periodical","env_steps":10,"tasks":[[0.1,0.2]]})"
      "\n";
  std::ofstream(file, std::ios::trunc) << good;
  auto controller = make_controller(spec, 1);
  replay_teacher_book(*controller, file, /*periodical=*/true);
  EXPECT_EQ(controller->episodes(), 1);
  EXPECT_EQ(controller->env_steps(), 10);

  const std::pair<const char*, const char*> damaged[] = {
      {R"({"env_steps":3})", R"(:1: the line has no key "kind")"},
      {R"({"kind":"train","env_steps":3,"task":[1],"return":0,"length":1,"success":true})",
       R"(:1: the line: "task" has 1 numbers; expected a task of 2 numbers)"},
      {R"({"kind":"train","env_steps":-3,"task":[1,1],"return":0,"length":1,"success":true})",
       R"(:1: the line: "env_steps" is -3; expected an integer >= 0)"},
      {R"({"kind":"train","env_steps":3,"task":[1,1],"return":"x","length":1,"success":true})",
       R"(:1: the line: "return" is "x"; expected a number)"},
      {R"({"kind":"periodical","env_steps":3,"tasks":[[1]]})", "a periodical task is not"},
      {R"({"kind":"sorcery"})", R"("kind" is "sorcery"; expected train, periodical or dump)"},
      {R"([1,2])", ":1: the line is not a JSON object"}};
  for (const auto& [line, message] : damaged) {
    std::ofstream(file, std::ios::trunc) << line << "\n" << good;
    auto fresh = make_controller(spec, 1);
    try {
      replay_teacher_book(*fresh, file, true);
      ADD_FAILURE() << "accepted: " << line;
    } catch (const UserError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
      EXPECT_NE(what.find(file.string() + ":1: "), std::string::npos) << what;
      EXPECT_NE(what.find(message), std::string::npos) << what;
    }
    EXPECT_EQ(fresh->episodes(), 0) << line;  // nothing heard
    EXPECT_THROW(check_teacher_book(file, 2), UserError) << line;
  }
  std::filesystem::remove(file);
}

}  // namespace
}  // namespace cradle::train

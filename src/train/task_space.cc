#include "train/task_space.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <climits>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "core/jsonl.h"
#include "teach/registry.h"
#include "train/families.h"
#include "train/run_json.h"

namespace cradle::train {
namespace {

// YAML -> JSON: maps keep their order; scalars become integers, numbers, booleans or strings.
nlohmann::ordered_json to_json(const YAML::Node& node) {
  if (node.IsMap()) {
    nlohmann::ordered_json out = nlohmann::ordered_json::object();
    for (const auto& item : node) out[item.first.as<std::string>()] = to_json(item.second);
    return out;
  }
  if (node.IsSequence()) {
    nlohmann::ordered_json out = nlohmann::ordered_json::array();
    for (const auto& item : node) out.push_back(to_json(item));
    return out;
  }
  if (node.IsNull()) return nullptr;
  const std::string text = node.Scalar();
  long i = 0;
  double d = 0;
  bool b = false;
  if (YAML::convert<long>::decode(node, i)) return i;
  if (YAML::convert<double>::decode(node, d)) return d;
  if (YAML::convert<bool>::decode(node, b)) return b;
  return text;
}

}  // namespace

CurriculumSpec parse_task_space(const std::string& yaml_text, const std::string& source,
                                bool need_teacher) {
  nlohmann::ordered_json j;
  try {
    j = to_json(YAML::Load(yaml_text));
  } catch (const YAML::Exception& e) {
    throw UserError(source + ": not valid YAML (" + e.msg + ")");
  }
  if (!j.is_object()) throw UserError(source + ": expected a mapping with teacher and params");
  const std::string keys =
      "teacher, params, teacher_params, expert_knowledge, success_threshold, reward_bounds, "
      "scale_reward, outcome";
  CurriculumSpec spec;
  auto wrong = [&](const std::string& key, const std::string& expected) {
    return UserError(source + ": " + key + " is " + j[key].dump() + "; expected " + expected);
  };
  for (const auto& [key, value] : j.items()) {
    if (key == "teacher") {
      if (!value.is_string()) throw wrong(key, "a teacher name");
      spec.teacher = value.get<std::string>();
    } else if (key == "params") {
      try {
        spec.space = teach::TaskSpace::from_json(value);
      } catch (const UserError& e) {
        throw UserError(source + ": " + e.what());
      }
    } else if (key == "teacher_params") {
      if (!value.is_object()) throw wrong(key, "a mapping of the teacher's parameters");
      spec.teacher_params = nlohmann::json::parse(value.dump());
    } else if (key == "expert_knowledge") {
      if (!value.is_string()) throw wrong(key, "none, low or high");
      spec.expert_knowledge = value.get<std::string>();
      try {
        teach::parse_expert_knowledge(spec.expert_knowledge);
      } catch (const UserError& e) {
        throw UserError(source + ": " + e.what());
      }
    } else if (key == "success_threshold") {
      if (!value.is_number()) throw wrong(key, "a number");
      spec.env_options.success_threshold = value.get<double>();
    } else if (key == "reward_bounds") {
      if (!value.is_array() || value.size() != 2 || !value[0].is_number() ||
          !value[1].is_number() || !(value[0].get<double>() < value[1].get<double>())) {
        throw wrong(key, "[lb, ub] with lb < ub");
      }
      spec.reward_lb = value[0].get<double>();
      spec.reward_ub = value[1].get<double>();
    } else if (key == "outcome") {
      if (value != "return" && value != "score") throw wrong(key, "return or score");
      spec.env_options.use_score = value == "score";
    } else if (key == "scale_reward") {
      if (!value.is_boolean()) throw wrong(key, "true or false");
      spec.scale_reward = value.get<bool>();
    } else {
      throw UserError(source + ": unknown key '" + key + "' (expected " + keys + ")");
    }
  }
  if (need_teacher && spec.teacher.empty())
    throw UserError(source + ": no teacher (e.g. teacher: ALP-GMM)");
  if (!j.contains("params")) {
    throw UserError(source + ": no params (e.g. params: {start_posture_range: [0, 1]})");
  }
  return spec;
}

CurriculumSpec load_task_space(const std::filesystem::path& file, bool need_teacher) {
  std::ifstream in(file);
  if (!in) throw UserError("--task-space '" + file.string() + "' cannot be read");
  std::stringstream text;
  text << in.rdbuf();
  return parse_task_space(text.str(), file.string(), need_teacher);
}

CurriculumSpec env_curriculum(const envs::EnvSpec& env) {
  if (env.parameters.empty()) {
    throw UserError("--teacher: " + env.id +
                    " has no task parameters for a teacher to set (`cradle envs` lists each "
                    "env's); give --task-space FILE.yml");
  }
  return family(env.family).curriculum(env);
}

std::shared_ptr<teach::TeacherController> make_controller(const CurriculumSpec& spec,
                                                          std::uint64_t seed) {
  teach::TeacherSetup setup{
      .name = spec.teacher,
      .mins = spec.space->mins(),
      .maxs = spec.space->maxs(),
      .seed = seed,
      .expert_knowledge = teach::parse_expert_knowledge(spec.expert_knowledge),
      .reward_lb = spec.reward_lb,
      .reward_ub = spec.reward_ub,
      .scale_reward = spec.scale_reward,
      .params = spec.teacher_params};
  setup.initial_dist = spec.initial_dist;
  // The teacher works in the shuffled space: the easy region's mean maps there.
  if (spec.shuffle_dimensions && setup.initial_dist) {
    const teach::DimensionShuffle shuffle(setup.mins, setup.maxs, seed);
    setup.initial_dist->mean = shuffle.to_shuffled(setup.initial_dist->mean);
  }
  return make_controller(spec, teach::make_teacher(setup), seed);
}

std::shared_ptr<teach::TeacherController> make_controller(const CurriculumSpec& spec,
                                                          std::unique_ptr<teach::Teacher> teacher,
                                                          std::uint64_t seed) {
  // The controller checks the teacher's dimension against the space's.
  return std::make_shared<teach::TeacherController>(
      std::move(teacher), *spec.space,
      teach::ControllerOptions{.seed = seed,
                               .shuffle_dimensions = spec.shuffle_dimensions,
                               .scale_reward = spec.scale_reward,
                               .reward_lb = spec.reward_lb,
                               .reward_ub = spec.reward_ub,
                               .test_set = spec.test_set.empty()
                                               ? teach::default_test_set(*spec.space, 1)
                                               : spec.test_set,
                               .keep_periodical_task_samples = spec.keep_periodical_task_samples});
}

namespace {

// Checks every line of a teacher book, then (with a controller) replays it.
void read_teacher_book(teach::TeacherController* controller, const std::filesystem::path& file,
                       bool periodical, std::size_t dims) {
  const std::string what = "a line of a run's teacher book";
  const std::string dim_text = "a task of " + std::to_string(dims) + " numbers";
  // Every line checked before the controller hears any (never a half-replayed teacher).
  std::vector<teach::EpisodeRecord> episodes;
  std::vector<teach::PeriodicalRecord> samples;
  std::vector<int> order;  // 0: the next episode, 1: the next periodical sample
  // read_jsonl names the file and line of a problem; `where` names the part of the line.
  read_jsonl(file, [&](const nlohmann::json& entry) -> std::string {
    try {
      const RunJson line("the line", entry, what);
      const std::string kind = line.string("kind");
      if (kind == "train") {
        teach::EpisodeRecord e{
            .env_steps = line.count("env_steps"),
            .task = line.floats("task"),
            .ret = line.number("return"),
            .length = static_cast<int>(std::min<long>(line.count("length"), INT_MAX)),
            .success = line.boolean("success")};
        if (e.task.size() != dims)
          throw UserError(line.where() + ": \"task\" has " + std::to_string(e.task.size()) +
                          " numbers; expected " + dim_text);
        episodes.push_back(std::move(e));
        order.push_back(0);
      } else if (kind == "periodical") {
        teach::PeriodicalRecord p{.env_steps = line.count("env_steps")};
        if (!line.json()["tasks"].is_array())
          throw UserError(line.where() + ": \"tasks\" is not a list; expected a list of tasks");
        for (const nlohmann::json& t : line.json()["tasks"]) {
          const RunJson task(line.where() + ": tasks", {{"task", t}}, what);
          p.tasks.push_back(task.floats("task"));
          if (p.tasks.back().size() != dims)
            throw UserError(line.where() + ": a periodical task is not " + dim_text);
        }
        samples.push_back(std::move(p));
        order.push_back(1);
      } else if (kind != "dump") {
        throw UserError(line.where() + ": \"kind\" is \"" + kind +
                        "\"; expected train, periodical or dump");
      }
    } catch (const UserError& e) {
      return e.what();
    }
    return "";
  });
  if (!controller) return;
  std::size_t next_episode = 0, next_sample = 0;
  for (int kind : order) {
    if (kind == 0) {
      const teach::EpisodeRecord& e = episodes[next_episode++];
      controller->replay_train_episode(e.task, e.ret, e.length, e.success, e.env_steps);
    } else if (periodical) {
      controller->replay_periodical(std::move(samples[next_sample++]));
    }
  }
}

}  // namespace

void check_teacher_book(const std::filesystem::path& file, int dims) {
  read_teacher_book(nullptr, file, false, static_cast<std::size_t>(dims));
}

void replay_teacher_book(teach::TeacherController& controller, const std::filesystem::path& file,
                         bool periodical) {
  read_teacher_book(&controller, file, periodical,
                    static_cast<std::size_t>(controller.space().dims()));
}

}  // namespace cradle::train

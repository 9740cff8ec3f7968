// A curriculum for any env that takes its task as reset options (`cradle train --task-space`):
// the YAML file names the teacher, the task space and the teacher's parameters (docs/curricula.md).
//   teacher: ALP-GMM                       # one of teach::teacher_names(); optional when the run
//                                          # names one or brings its own (TeacherFactory)
//   params:                                # name: [min, max] | [min, max, n] | [[min, max], ...]
//     start_posture_range: [0, 1]
//   teacher_params: {fit_rate: 50}         # the reference's kwarg names (optional)
//   expert_knowledge: none                 # none | low | high (optional, default none)
//   success_threshold: 100                 # optional: return above it is a success; default the
//                                          # env's info flag is_success
//   reward_bounds: [-100, 100]             # optional: for scale_reward and ADR's thresholds
//   scale_reward: false                    # optional
//   outcome: return                        # optional: return (default) or score (the env's
//                                          # score() of the episode, e.g. BabyBench's behaviour)
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "envs/registry.h"
#include "teach/controller.h"
#include "teach/registry.h"
#include "train/curriculum_env.h"

namespace cradle::train {

struct CurriculumSpec {
  std::string teacher;
  std::optional<teach::TaskSpace> space;  // set by parse_task_space
  nlohmann::json teacher_params = nlohmann::json::object();
  std::string expert_knowledge = "none";
  CurriculumOptions env_options;  // the success threshold
  double reward_lb = -100, reward_ub = 100;
  bool scale_reward = false;
  // The task space's easy region, which teachers start from with high expert knowledge (Stump
  // Tracks' no-stumps corner); task-space files have none.
  std::optional<teach::DiagGaussian> initial_dist;
  // A family's own curriculum (not in task-space files): the teacher works in a shuffled space
  // (TeachMyAgent's rugged difficulty), the controller keeps snapshots of 100 sampled tasks every
  // this many env steps (0: none), and evaluations walk this test set (empty: the default one).
  bool shuffle_dimensions = false;
  long keep_periodical_task_samples = 0;
  std::vector<teach::Task> test_set;
};

// Parses the YAML text (`source` names it in errors). UserError, one line, for an unknown key,
// missing params (or a missing teacher when need_teacher), malformed bounds or a value of the
// wrong type.
CurriculumSpec parse_task_space(const std::string& yaml_text, const std::string& source,
                                bool need_teacher = true);
CurriculumSpec load_task_space(const std::filesystem::path& file, bool need_teacher = true);

// The curriculum of `cradle train --env ID --teacher T` without a task-space file: every task
// parameter the env declares (envs/registry.h; `cradle envs`), in its declared range, with its
// family's facts (train/families.h). TeachMyAgent: the benchmark's (return bounds [-150, 350],
// Parkour 360, Stump Tracks' easy corner, expert knowledge high, as `cradle tma run`); BabyBench:
// the teacher hears the behaviour score (the env's reward is 0); MIMo and SaMI: the return,
// success by the env's is_success flag. The teacher's name is left to the run. UserError for an
// env without task parameters.
CurriculumSpec env_curriculum(const envs::EnvSpec& env);

// A teacher of the caller's own (e.g. a Python object's, src/python/python_teacher.h) for a task
// space, seeded by the run; it replaces the file's named teacher.
using TeacherFactory = std::function<std::unique_ptr<teach::Teacher>(const teach::TaskSpace& space,
                                                                     std::uint64_t seed)>;

// The controller of a spec: its teacher seeded with `seed` (UserError for an unknown teacher or
// a bad parameter), in the shuffled space when the spec shuffles (the easy region's mean mapped
// there).
std::shared_ptr<teach::TeacherController> make_controller(const CurriculumSpec& spec,
                                                          std::uint64_t seed);
// The same controller around a ready teacher (spec.teacher, teacher_params and expert_knowledge
// unused): UserError for a null teacher or one of another dimension than the space.
std::shared_ptr<teach::TeacherController> make_controller(const CurriculumSpec& spec,
                                                          std::unique_ptr<teach::Teacher> teacher,
                                                          std::uint64_t seed);

// A resumed run's teacher hears its book (the run's teacher.jsonl) again, in order: the training
// episodes and, with `periodical`, the periodical task samples; teacher dumps are skipped. Every
// line is checked first (its kind, a task of the controller's dimension, the types of return,
// length, success and env_steps): a damaged line is a one-line UserError naming file, line and key,
// and the controller hears nothing.
void replay_teacher_book(teach::TeacherController& controller, const std::filesystem::path& file,
                         bool periodical);
// The same checks alone, for a task space of `dims` dimensions (before a resume changes any file).
void check_teacher_book(const std::filesystem::path& file, int dims);

}  // namespace cradle::train

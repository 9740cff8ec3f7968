// Teachers by name, as TeachMyAgent's run.py knows them ("ALP-GMM", "Self-Paced", ...), with the
// expert-knowledge levels of its teacher_args_handler folded into one enum (spec tma_sami.md §1.3).
#pragma once

#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "teach/teacher.h"

namespace cradle::teach {

// How much the teacher may know about the env: none (not even a success notion), low (reward
// thresholds and success), high (also the env's easy region, SPDL's target).
enum class ExpertKnowledge { none, low, high };

// "none" or "no", "low", "high"; anything else throws UserError.
ExpertKnowledge parse_expert_knowledge(std::string_view text);

// `--teacher-param key=value` flags as a teacher's parameters (TeacherSetup::params), each value
// as JSON when it parses as JSON, else as a string. UserError naming the flag (control characters
// shown as \xNN, so the message stays one line) for one without a key or '=', and for a key given
// twice, whose first value would be dropped.
nlohmann::json parse_teacher_params(const std::vector<std::string>& flags);
// "none", "low" or "high".
const char* expert_knowledge_name(ExpertKnowledge ek);

struct TeacherSetup {
  std::string name;  // one of teacher_names()
  std::vector<float> mins, maxs;
  std::uint64_t seed = 0;
  ExpertKnowledge expert_knowledge = ExpertKnowledge::none;
  std::optional<DiagGaussian> initial_dist;  // the env's easy region (Stump Tracks only)
  std::optional<DiagGaussian> target_dist;   // SPDL's target (the whole box when absent)
  double reward_lb = -100, reward_ub = 100;  // env return bounds (for scaled thresholds)
  bool scale_reward = false;                 // the teacher sees returns mapped to [0, 1]
  // Teacher kwargs by the reference's names (e.g. {"fit_rate": 150, "random_task_ratio": 0.05});
  // an unknown key or a wrong type throws UserError naming it.
  nlohmann::json params = nlohmann::json::object();
};

// Builds the named teacher. Throws UserError on an unknown name, a bad parameter, or an expert
// knowledge level the reference refuses (ADR, GoalGAN and Setter-Solver need at least "low").
std::unique_ptr<Teacher> make_teacher(const TeacherSetup& setup);

// The valid names, in the reference's order.
const std::vector<std::string>& teacher_names();

}  // namespace cradle::teach

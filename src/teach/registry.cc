// Teachers by name: reads the reference's kwargs from JSON into each teacher's parameter struct and
// applies the expert-knowledge rules of TeachMyAgent's teacher_args_handler (spec §1.3).
#include "teach/registry.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <variant>

#include "core/error.h"
#include "core/text.h"

namespace cradle::teach {
namespace {

// Reads typed kwargs out of a JSON object and refuses the keys nobody read.
class ParamReader {
 public:
  ParamReader(const nlohmann::json& params, std::string teacher)
      : params_(params), teacher_(std::move(teacher)) {
    if (!params_.is_object())
      throw UserError(teacher_ + ": params must be a JSON object of keyword arguments, got " +
                      std::string(params_.type_name()));
  }

  void get(const char* key, int& out) {
    if (const auto* v = find(key)) {
      if (!v->is_number_integer()) fail(key, "an integer", *v);
      out = v->get<int>();
    }
  }
  void get(const char* key, long& out) {
    if (const auto* v = find(key)) {
      if (!v->is_number_integer()) fail(key, "an integer", *v);
      out = v->get<long>();
    }
  }
  void get(const char* key, double& out) {
    if (const auto* v = find(key)) {
      if (!v->is_number()) fail(key, "a number", *v);
      out = v->get<double>();
    }
  }
  void get(const char* key, float& out) {
    double d = out;
    get(key, d);
    out = static_cast<float>(d);
  }
  void get(const char* key, bool& out) {
    if (const auto* v = find(key)) {
      if (!v->is_boolean()) fail(key, "true or false", *v);
      out = v->get<bool>();
    }
  }
  void get(const char* key, std::string& out) {
    if (const auto* v = find(key)) {
      if (!v->is_string()) fail(key, "a string", *v);
      out = v->get<std::string>();
    }
  }
  void get(const char* key, std::vector<int>& out) {
    if (const auto* v = find(key)) {
      if (!v->is_array() || v->empty()) fail(key, "a non-empty list of integers", *v);
      out.clear();
      for (const auto& e : *v) {
        if (!e.is_number_integer()) fail(key, "a non-empty list of integers", *v);
        out.push_back(e.get<int>());
      }
    }
  }
  // A key the reference has but only one value of which we support.
  template <typename T>
  void require(const char* key, T supported, const char* why) {
    T value = supported;
    get(key, value);
    if (value != supported)
      throw UserError(teacher_ + ": " + key + " = " + nlohmann::json(value).dump() +
                      " is not supported (" + why + "); expected " +
                      nlohmann::json(supported).dump());
  }
  // A key the reference has that we do not implement: only null (its default) is accepted.
  void refuse(const char* key, const char* why) {
    if (const auto* v = find(key))
      throw UserError(teacher_ + ": " + key + " = " + v->dump() + " is not supported (" + why +
                      "); expected null");
  }
  // Throws UserError naming the first key no get() asked for.
  void finish() const {
    for (const auto& [key, value] : params_.items()) {
      if (known_.count(key)) continue;
      std::string valid;
      for (const auto& k : known_) valid += (valid.empty() ? "" : ", ") + k;
      throw UserError(teacher_ + ": unknown parameter '" + key +
                      "'; expected one of: " + (valid.empty() ? std::string("(none)") : valid));
    }
  }

 private:
  const nlohmann::json* find(const char* key) {
    known_.insert(key);
    auto it = params_.find(key);
    return it == params_.end() || it->is_null() ? nullptr : &*it;
  }
  [[noreturn]] void fail(const char* key, const char* expected, const nlohmann::json& v) const {
    throw UserError(teacher_ + ": parameter '" + key + "' is " + v.dump() + "; expected " +
                    expected);
  }

  const nlohmann::json& params_;
  std::string teacher_;
  std::set<std::string> known_;
};

// The return `value` mapped from [lb, ub] to [0, 1] and clipped (np.interp).
double scale(double value, const TeacherSetup& s) {
  return std::clamp((value - s.reward_lb) / (s.reward_ub - s.reward_lb), 0.0, 1.0);
}

// One kwarg: the reference's name and the parameter field it sets.
template <typename P>
struct Kwarg {
  const char* key;
  std::variant<int P::*, long P::*, float P::*, double P::*, bool P::*, std::string P::*,
               std::vector<int> P::*>
      field;
};

// The kwargs of `table` read into P's defaults; then any key nobody asked for is refused (so a
// teacher's require and refuse calls come first).
template <typename P>
P read_kwargs(ParamReader& r, std::initializer_list<Kwarg<P>> table) {
  P p;
  for (const Kwarg<P>& k : table) std::visit([&](auto field) { r.get(k.key, p.*field); }, k.field);
  r.finish();
  return p;
}

std::unique_ptr<Teacher> make_adr(const TeacherSetup& s, ParamReader& r) {
  using P = AdrParams;
  P p = read_kwargs<P>(r, {{"step_size", &P::step_size},
                           {"boundary_sampling_p", &P::boundary_prob},
                           {"queue_len", &P::queue_len},
                           {"max_reward_thr", &P::max_reward_thr},
                           {"min_reward_thr", &P::min_reward_thr}});
  // Thresholds follow the returns into [0, 1] when the teacher sees scaled returns.
  if (s.scale_reward) {
    p.max_reward_thr = scale(p.max_reward_thr, s);
    p.min_reward_thr = scale(p.min_reward_thr, s);
  }
  // High expert knowledge: the box grows from the centre of the env's easy region.
  if (s.expert_knowledge == ExpertKnowledge::high && s.initial_dist)
    p.initial_point = s.initial_dist->mean;
  return make_adr_teacher(s.mins, s.maxs, s.seed, std::move(p));
}

std::unique_ptr<Teacher> make_riac(const TeacherSetup& s, ParamReader& r) {
  using P = RiacParams;
  r.require("sampling_in_leaves_only", false, "regions are drawn among all nodes");
  const P p = read_kwargs<P>(r, {{"max_region_size", &P::max_region_size},
                                 {"alp_window_size", &P::alp_window},
                                 {"nb_split_attempts", &P::nb_split_attempts},
                                 {"min_region_size", &P::min_region_size},
                                 {"min_dims_range_ratio", &P::min_dims_range_ratio},
                                 {"discard_ratio", &P::discard_ratio}});
  return make_riac_teacher(s.mins, s.maxs, s.seed, p);
}

std::unique_ptr<Teacher> make_alp_gmm(const TeacherSetup& s, ParamReader& r) {
  using P = AlpGmmParams;
  r.require("nb_em_init", 1, "one EM start per k");
  r.require("weighted_gmm", false, "plain GMMs only");
  P p = read_kwargs<P>(r, {{"fit_rate", &P::fit_rate},
                           {"potential_ks", &P::potential_ks},
                           {"random_task_ratio", &P::random_task_ratio},
                           {"gmm_fitness_func", &P::criterion}});
  if (s.expert_knowledge == ExpertKnowledge::high) p.initial_dist = s.initial_dist;
  return make_alp_gmm_teacher(s.mins, s.maxs, s.seed, std::move(p));
}

std::unique_ptr<Teacher> make_covar_gmm(const TeacherSetup& s, ParamReader& r) {
  using P = CovarGmmParams;
  P p = read_kwargs<P>(r, {{"fit_rate", &P::fit_rate},
                           {"potential_ks", &P::potential_ks},
                           {"random_task_ratio", &P::random_task_ratio},
                           {"absolute_lp", &P::absolute_lp}});
  if (s.expert_knowledge == ExpertKnowledge::high) p.initial_dist = s.initial_dist;
  return make_covar_gmm_teacher(s.mins, s.maxs, s.seed, std::move(p));
}

std::unique_ptr<Teacher> make_self_paced(const TeacherSetup& s, ParamReader& r) {
  using P = SelfPacedParams;
  r.refuse("std_lower_bound", "no std lower bound");
  r.refuse("kl_threshold", "no std lower bound");
  r.refuse("cg_parameters", "a direct natural-gradient solve");
  P p = read_kwargs<P>(r, {{"update_frequency", &P::update_frequency},
                           {"update_offset", &P::update_offset},
                           {"alpha_offset", &P::alpha_offset},
                           {"zeta", &P::zeta},
                           {"max_kl", &P::max_kl},
                           {"use_avg_performance", &P::use_avg_performance},
                           {"discount_factor", &P::discount_factor}});
  // Only high expert knowledge gives the env's easy region and target (spec §1.3, fixed labels).
  if (s.expert_knowledge == ExpertKnowledge::high) {
    p.initial_dist = s.initial_dist;
    p.target_dist = s.target_dist;
  }
  return make_self_paced_teacher(s.mins, s.maxs, s.seed, std::move(p));
}

std::unique_ptr<Teacher> make_goal_gan(const TeacherSetup& s, ParamReader& r) {
  using P = GoalGanParams;
  P p = read_kwargs<P>(r, {{"state_noise_level", &P::state_noise_level},
                           {"success_distance_threshold", &P::success_distance_threshold},
                           {"update_size", &P::update_size},
                           {"n_rollouts", &P::n_rollouts},
                           {"goid_lb", &P::goid_lb},
                           {"goid_ub", &P::goid_ub},
                           {"p_old", &P::p_old},
                           {"use_pretrained_samples", &P::use_pretrained_samples},
                           {"pretrain_samples", &P::pretrain_samples},
                           {"pretrain_iterations", &P::pretrain_iterations},
                           {"train_iterations", &P::train_iterations},
                           {"batch_size", &P::batch_size},
                           {"lr", &P::lr}});
  // High expert knowledge: always pretrained, on the env's easy region.
  if (s.expert_knowledge == ExpertKnowledge::high) {
    p.use_pretrained_samples = true;
    p.initial_dist = s.initial_dist;
  }
  return make_goal_gan_teacher(s.mins, s.maxs, s.seed, std::move(p));
}

std::unique_ptr<Teacher> make_setter_solver(const TeacherSetup& s, ParamReader& r) {
  using P = SetterSolverParams;
  const P p = read_kwargs<P>(r, {{"update_frequency", &P::update_frequency},
                                 {"setter_loss_noise_ub", &P::setter_loss_noise_ub},
                                 {"setter_hidden_size", &P::setter_hidden_size},
                                 {"lr", &P::lr}});
  return make_setter_solver_teacher(s.mins, s.maxs, s.seed, p);
}

struct Entry {
  const char* name;
  bool needs_success;  // refused at expert knowledge "none" (the reference raises)
  std::unique_ptr<Teacher> (*make)(const TeacherSetup&, ParamReader&);
};

const std::vector<Entry>& entries() {
  static const std::vector<Entry> all = {
      {"Random", false,
       [](const TeacherSetup& s, ParamReader& r) {
         r.finish();
         return make_random_teacher(s.mins, s.maxs, s.seed);
       }},
      {"ADR", true, make_adr},
      {"ALP-GMM", false, make_alp_gmm},
      {"Covar-GMM", false, make_covar_gmm},
      {"RIAC", false, make_riac},
      {"Self-Paced", false, make_self_paced},
      {"GoalGAN", true, make_goal_gan},
      {"Setter-Solver", true, make_setter_solver},
  };
  return all;
}

std::string joined_names() {
  std::string out;
  for (const auto& n : teacher_names()) out += (out.empty() ? "" : ", ") + n;
  return out;
}

}  // namespace

nlohmann::json parse_teacher_params(const std::vector<std::string>& flags) {
  nlohmann::json params = nlohmann::json::object();
  for (const std::string& flag : flags) {
    const size_t eq = flag.find('=');
    if (eq == std::string::npos || eq == 0)
      throw UserError("--teacher-param '" + printable(flag) + "' (expected key=value)");
    const std::string key = flag.substr(0, eq), value = flag.substr(eq + 1);
    if (params.contains(key))
      throw UserError("--teacher-param " + printable(key) +
                      " is given twice (expected each key once)");
    params[key] =
        nlohmann::json::accept(value) ? nlohmann::json::parse(value) : nlohmann::json(value);
  }
  return params;
}

ExpertKnowledge parse_expert_knowledge(std::string_view text) {
  if (text == "none" || text == "no") return ExpertKnowledge::none;
  if (text == "low") return ExpertKnowledge::low;
  if (text == "high") return ExpertKnowledge::high;
  throw UserError("expert knowledge '" + std::string(text) +
                  "'; expected none (or no), low or high");
}

const char* expert_knowledge_name(ExpertKnowledge ek) {
  switch (ek) {
    case ExpertKnowledge::none:
      return "none";
    case ExpertKnowledge::low:
      return "low";
    case ExpertKnowledge::high:
      return "high";
  }
  return "none";
}

const std::vector<std::string>& teacher_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> v;
    for (const auto& e : entries()) v.emplace_back(e.name);
    return v;
  }();
  return names;
}

std::unique_ptr<Teacher> make_teacher(const TeacherSetup& setup) {
  // The name first: everything else depends on which teacher it is.
  const auto& all = entries();
  const auto it =
      std::find_if(all.begin(), all.end(), [&](const Entry& e) { return setup.name == e.name; });
  if (it == all.end())
    throw UserError("unknown teacher '" + setup.name + "'; expected one of: " + joined_names());
  // The reference refuses these teachers without a success notion or reward thresholds.
  if (it->needs_success && setup.expert_knowledge == ExpertKnowledge::none)
    throw UserError("teacher " + setup.name +
                    " cannot run with expert knowledge none (it needs at least reward "
                    "thresholds or a success notion); expected low or high");
  // Reward bounds matter only when returns are scaled.
  if (setup.scale_reward && !(std::isfinite(setup.reward_lb) && std::isfinite(setup.reward_ub) &&
                              setup.reward_lb < setup.reward_ub))
    throw UserError("teacher " + setup.name + ": reward bounds [" +
                    std::to_string(setup.reward_lb) + ", " + std::to_string(setup.reward_ub) +
                    "]; expected finite lb < ub to scale rewards");
  ParamReader reader(setup.params, setup.name);
  return it->make(setup, reader);
}

}  // namespace cradle::teach

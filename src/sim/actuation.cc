#include "sim/actuation.h"

#include <stdexcept>
#include <string>
#include <string_view>

namespace cradle::sim {

std::vector<int> mimo_actuators(const mjModel* m) {
  constexpr std::string_view kPrefix = "act:";
  std::vector<int> ids;
  for (int i = 0; i < m->nu; ++i) {
    const char* name = mj_id2name(m, mjOBJ_ACTUATOR, i);
    if (name && std::string_view(name).starts_with(kPrefix)) ids.push_back(i);
  }
  return ids;
}

namespace {

std::string actuator_label(const mjModel* m, int actuator) {
  const char* name = mj_id2name(m, mjOBJ_ACTUATOR, actuator);
  return name ? name : "actuator " + std::to_string(actuator);
}

}  // namespace

int actuated_joint(const mjModel* m, int actuator) {
  if (m->actuator_trntype[actuator] != mjTRN_JOINT) {
    throw std::runtime_error(actuator_label(m, actuator) + " does not drive a joint");
  }
  const int joint = m->actuator_trnid[2 * actuator];
  if (m->jnt_type[joint] != mjJNT_HINGE && m->jnt_type[joint] != mjJNT_SLIDE) {
    throw std::runtime_error(actuator_label(m, actuator) +
                             " drives a joint that is neither a hinge nor a slide");
  }
  return joint;
}

void require_actuator(bool ok, const mjModel* m, int actuator, ActuationModel kind,
                      std::string_view problem) {
  if (ok) return;
  throw std::runtime_error(std::string(actuation_model_name(kind)) + " actuation: " +
                           actuator_label(m, actuator) + " " + std::string(problem));
}

std::unique_ptr<Actuation> make_actuation(ActuationModel kind, const mjModel* m) {
  switch (kind) {
    case ActuationModel::kSpringDamper:
      return make_spring_damper(m);
    case ActuationModel::kMuscle:
      return make_muscle(m);
    case ActuationModel::kPositional:
      return make_positional(m);
  }
  throw std::runtime_error("unknown actuation model");
}

}  // namespace cradle::sim

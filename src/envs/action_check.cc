#include "envs/action_check.h"

#include <cmath>
#include <string>

#include "core/error.h"

namespace cradle::envs {

void check_finite_actions(std::span<const double> actions, int action_size) {
  for (size_t k = 0; k < actions.size(); ++k) {
    if (std::isfinite(actions[k])) continue;
    const std::string value = std::isnan(actions[k]) ? "nan" : (actions[k] > 0 ? "inf" : "-inf");
    const std::string where = action_size > 0 ? "action " + std::to_string(k % action_size) +
                                                    " of env " + std::to_string(k / action_size)
                                              : "action " + std::to_string(k);
    throw UserError(where + " is " + value + "; expected finite values");
  }
}

}  // namespace cradle::envs

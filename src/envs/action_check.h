// Non-finite actions (NaN, inf) are refused at the env API: MuJoCo would silently zero the
// controls and hand back NaN observations. One check for single envs, vectors and Python.
#pragma once

#include <span>

namespace cradle::envs {

// Throws UserError naming the first non-finite value ("action 3 of env 1 is nan; expected finite
// values"); `action_size` splits a batch into envs (0: a single env's action).
void check_finite_actions(std::span<const double> actions, int action_size = 0);

}  // namespace cradle::envs

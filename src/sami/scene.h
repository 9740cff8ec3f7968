// A SaMI env's model as an MJCF file that MuJoCo's `simulate` opens: the shared robot with the
// current episode's hidden parameters (scaled masses and damping, shrunk and red crippled geoms,
// Panda's table and contact frictions) and its masked actuators (gear 0).
#pragma once

#include <string>

#include "sami/env.h"

namespace cradle::sami {

// The MJCF text of env.model() after its last reset. Every body carries an explicit inertial with
// the env's exact mass and inertia (SaMI scales the mass alone, which geometry cannot express);
// the other numbers are MuJoCo's writer's (6 significant digits). The text is compiled and
// checked against the env's arrays before it is returned. Uses MuJoCo's last-loaded-XML writer:
// call it where no other thread loads MJCF at the same time.
std::string scene_xml(const SamiEnv& env);

}  // namespace cradle::sami

// A learner file that reaches into a concrete env: the floor check must refuse it
// (ctest floor_check_refuses_a_concrete_env).
#pragma once

#include "envs/babybench.h"
#include "envs/env.h"

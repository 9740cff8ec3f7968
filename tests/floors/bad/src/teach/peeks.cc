// A teacher file that reaches into a sample env: the floor check must refuse it (ctest
// floor_check_refuses_a_concrete_env_in_teach).
#include "envs/env.h"
#include "envs/mimo/sample_env.h"

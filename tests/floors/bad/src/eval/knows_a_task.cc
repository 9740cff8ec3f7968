// An evaluation file that knows a concrete task: the floor check must refuse it (ctest
// floor_check_refuses_a_concrete_task_in_eval); the task's panels come through envs/task.h.
#include "envs/hand_regard.h"
#include "envs/task.h"

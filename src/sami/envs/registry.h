// The SaMI registration table: one line per env and one per robot model. Everything else asks
// it: EnvId and Robot are made from these lines (sami/task.h, sami/models.h), and the table of
// env definitions (envs/registry.cc, env_def()) gives the names, the specs, the task sets, the
// models and the step to env_from_name, env_spec, split_sets, make_env and robot_xml.
//
// An env line is ENV(enumerator, file): the EnvId enumerator and the env's file under
// src/sami/envs/, whose function envs::<file>() returns the env's definition (envs/env_def.h).
// The order is EnvId's: `cradle sami info`, the env registry and the fingerprints list the envs
// in it, so a new env goes at the end.
#pragma once

#define CRADLE_SAMI_ENVS(ENV)                    \
  ENV(kHalfCheetah, half_cheetah)                \
  ENV(kAnt, ant)                                 \
  ENV(kHopper, hopper)                           \
  ENV(kWalker, walker)                           \
  ENV(kSlimHumanoid, slim_humanoid)              \
  ENV(kHumanoidStandup, humanoid_standup)        \
  ENV(kCrippleHalfCheetah, cripple_half_cheetah) \
  ENV(kCrippleAnt, cripple_ant)                  \
  ENV(kCrippleHopper, cripple_hopper)            \
  ENV(kCrippleWalker, cripple_walker)            \
  ENV(kWalkerHopper, walker_hopper)              \
  ENV(kPandaPush, panda_push)

// The robot models: the Robot enumerators. One env definition of each robot gives its MJCF text
// (EnvDef::model); the others name the robot and share its compiled model.
#define CRADLE_SAMI_ROBOTS(ROBOT) \
  ROBOT(kHalfCheetah)             \
  ROBOT(kAnt)                     \
  ROBOT(kHopper)                  \
  ROBOT(kWalker)                  \
  ROBOT(kHumanoid)                \
  ROBOT(kPanda)

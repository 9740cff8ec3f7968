// What a compiled scene contains: MIMo's counts, mass and height, and MuJoCo's sizes
// (`cradle model-info`).
#pragma once

#include <mujoco/mujoco.h>

#include <nlohmann/json.hpp>
#include <string>

namespace cradle::scene {

struct ModelSummary {
  std::string mimo_version;  // "v1" or "v2"
  int n_joints = 0;          // robot:* joints
  int n_actuators = 0;       // act:* actuators
  int n_torque_sensors = 0;  // proprio:* sensors
  int n_bodies = 0;          // bodies in the subtree of "hip"
  int n_geoms = 0;           // geoms of those bodies
  double total_mass = 0;     // kg, subtree of "hip"
  double height = 0;         // m, zero pose, lowest geom point to top of head along MIMo's z
  int nq = 0, nv = 0, nu = 0, nbody = 0, ngeom = 0, neq = 0, ncam = 0, nsensordata = 0;
  long ntexdata = 0;  // bytes of texture data in the compiled model
  double timestep = 0;
};

ModelSummary summarize(const mjModel* m);
nlohmann::json to_json(const ModelSummary& summary);

// Body ids of the subtree rooted at the body named root (root first), in id order.
std::vector<int> subtree_bodies(const mjModel* m, const char* root);

}  // namespace cradle::scene

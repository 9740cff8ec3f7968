#include "scene/summary.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string_view>
#include <vector>

namespace cradle::scene {
namespace {

int count_prefixed(const mjModel* m, mjtObj type, int n, std::string_view prefix) {
  int count = 0;
  for (int i = 0; i < n; ++i) {
    const char* name = mj_id2name(m, type, i);
    if (name && std::string_view(name).starts_with(prefix)) ++count;
  }
  return count;
}

// Half extent of a geom along unit world direction u, given its world rotation (row-major).
double half_extent(const mjModel* m, int g, const mjtNum* xmat, const mjtNum* u) {
  const mjtNum* size = m->geom_size + 3 * g;
  // Projection of the geom's local axis k onto u.
  auto axis_dot = [&](int k) { return xmat[k] * u[0] + xmat[3 + k] * u[1] + xmat[6 + k] * u[2]; };
  switch (m->geom_type[g]) {
    case mjGEOM_SPHERE:
      return size[0];
    case mjGEOM_CAPSULE:
      return size[0] + size[1] * std::abs(axis_dot(2));
    case mjGEOM_CYLINDER: {
      const double c = std::abs(axis_dot(2));
      return size[1] * c + size[0] * std::sqrt(std::max(0.0, 1 - c * c));
    }
    case mjGEOM_BOX:
      return size[0] * std::abs(axis_dot(0)) + size[1] * std::abs(axis_dot(1)) +
             size[2] * std::abs(axis_dot(2));
    default:
      return m->geom_rbound[g];
  }
}

}  // namespace

std::vector<int> subtree_bodies(const mjModel* m, const char* root) {
  std::vector<int> out;
  const int root_id = mj_name2id(m, mjOBJ_BODY, root);
  if (root_id < 0) return out;
  for (int b = 0; b < m->nbody; ++b) {
    // Walk up the parent chain; the world body (0) is its own parent.
    for (int a = b; a > 0; a = m->body_parentid[a]) {
      if (a == root_id) {
        out.push_back(b);
        break;
      }
    }
  }
  return out;
}

ModelSummary summarize(const mjModel* m) {
  ModelSummary s;
  s.n_joints = count_prefixed(m, mjOBJ_JOINT, m->njnt, "robot:");
  s.n_actuators = count_prefixed(m, mjOBJ_ACTUATOR, m->nu, "act:");
  s.n_torque_sensors = count_prefixed(m, mjOBJ_SENSOR, m->nsensor, "proprio:");
  s.mimo_version = mj_name2id(m, mjOBJ_BODY, "right_fingers") >= 0 ? "v1" : "v2";

  const std::vector<int> bodies = subtree_bodies(m, "hip");
  s.n_bodies = static_cast<int>(bodies.size());
  for (int b : bodies) {
    s.total_mass += m->body_mass[b];
    s.n_geoms += m->body_geomnum[b];
  }

  // Height in the zero pose: extent of MIMo's geoms along the z axis of his root frame.
  mjData* d = mj_makeData(m);
  mj_kinematics(m, d);
  const int root = mj_name2id(m, mjOBJ_BODY, "mimo_location");
  if (root >= 0 && !bodies.empty()) {
    const mjtNum up[3] = {d->xmat[9 * root + 2], d->xmat[9 * root + 5], d->xmat[9 * root + 8]};
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (int g = 0; g < m->ngeom; ++g) {
      if (std::find(bodies.begin(), bodies.end(), m->geom_bodyid[g]) == bodies.end()) continue;
      const mjtNum* p = d->geom_xpos + 3 * g;
      const double center = p[0] * up[0] + p[1] * up[1] + p[2] * up[2];
      const double half = half_extent(m, g, d->geom_xmat + 9 * g, up);
      lo = std::min(lo, center - half);
      hi = std::max(hi, center + half);
    }
    s.height = hi - lo;
  }
  mj_deleteData(d);

  s.nq = m->nq;
  s.nv = m->nv;
  s.nu = m->nu;
  s.nbody = m->nbody;
  s.ngeom = m->ngeom;
  s.neq = m->neq;
  s.ncam = m->ncam;
  s.nsensordata = m->nsensordata;
  s.ntexdata = m->ntexdata;
  s.timestep = m->opt.timestep;
  return s;
}

nlohmann::json to_json(const ModelSummary& s) {
  return {{"mimo_version", s.mimo_version},
          {"n_joints", s.n_joints},
          {"n_actuators", s.n_actuators},
          {"n_torque_sensors", s.n_torque_sensors},
          {"n_bodies", s.n_bodies},
          {"n_geoms", s.n_geoms},
          {"total_mass", s.total_mass},
          {"height", s.height},
          {"nq", s.nq},
          {"nv", s.nv},
          {"nu", s.nu},
          {"nbody", s.nbody},
          {"ngeom", s.ngeom},
          {"neq", s.neq},
          {"ncam", s.ncam},
          {"nsensordata", s.nsensordata},
          {"ntexdata", s.ntexdata},
          {"timestep", s.timestep}};
}

}  // namespace cradle::scene

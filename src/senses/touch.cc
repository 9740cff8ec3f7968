#include "senses/touch.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include "core/error.h"

namespace cradle::senses {
namespace {

// A sensor counts as hidden when it lies deeper than this inside another geom of its body, so
// points on shared faces stay active.
constexpr double kInsideTolerance = 1e-9;
// Contacts whose normal force is below this carry no touch (the reference's threshold).
constexpr double kMinNormalForce = 1e-9;

// Spacing table entry: a body name without its side prefix and its spacing (m).
struct Spacing {
  const char* name;
  double spacing;
  bool sided;  // true: exists as left_<name> and right_<name>
};

// DEFAULT_TOUCH_PARAMS: the v1 spacings (mitten hands).
constexpr Spacing kV1Spacings[] = {
    {"hip", 0.025, false},      {"lower_body", 0.025, false}, {"upper_body", 0.030, false},
    {"head", 0.013, false},     {"eye", 1.0, true},           {"upper_arm", 0.024, true},
    {"lower_arm", 0.024, true}, {"hand", 0.007, true},        {"fingers", 0.002, true},
    {"upper_leg", 0.027, true}, {"lower_leg", 0.038, true},   {"foot", 0.015, true},
    {"toes", 0.010, true},
};

// DEFAULT_TOUCH_PARAMS_V2 additions: five-finger segments and the big toe (v1 "fingers" is gone).
constexpr Spacing kV2Extras[] = {
    {"big_toe", 0.010, true},   {"ffdistal", 0.002, true},     {"mfdistal", 0.002, true},
    {"rfdistal", 0.002, true},  {"lfdistal", 0.002, true},     {"thdistal", 0.002, true},
    {"ffmiddle", 0.004, true},  {"mfmiddle", 0.004, true},     {"rfmiddle", 0.004, true},
    {"lfmiddle", 0.004, true},  {"thhub", 0.004, true},        {"ffknuckle", 0.004, true},
    {"mfknuckle", 0.004, true}, {"rfknuckle", 0.004, true},    {"lfknuckle", 0.004, true},
    {"thbase", 0.004, true},    {"lfmetacarpal", 0.007, true},
};

// A geom's pose in its body's frame: p_body = rot * p_geom + pos.
struct Pose {
  std::array<double, 9> rot;
  Point3 pos;
};

Point3 to_body(const Pose& pose, const Point3& p) {
  Point3 out;
  for (int i = 0; i < 3; ++i) {
    out[i] = pose.pos[i] + pose.rot[3 * i] * p[0] + pose.rot[3 * i + 1] * p[1] +
             pose.rot[3 * i + 2] * p[2];
  }
  return out;
}

Point3 to_geom(const Pose& pose, const Point3& p) {
  const Point3 d = {p[0] - pose.pos[0], p[1] - pose.pos[1], p[2] - pose.pos[2]};
  Point3 out;
  for (int i = 0; i < 3; ++i) {
    out[i] = pose.rot[i] * d[0] + pose.rot[3 + i] * d[1] + pose.rot[6 + i] * d[2];
  }
  return out;
}

double dist2(const Point3& a, const Point3& b) {
  const double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
  return dx * dx + dy * dy + dz * dz;
}

// One collision geom of a sensing body during generation.
struct GeomSensors {
  int id;
  Shape shape;
  Pose pose;
  bool single;
  std::vector<Point3> points;  // body frame
};

}  // namespace

std::map<std::string, double> default_touch_scales(model::MimoVersion version,
                                                   const GroupFlags& groups, double scale) {
  std::map<std::string, double> out;
  auto add = [&](const Spacing& entry) {
    std::vector<std::string> names;
    if (entry.sided) {
      names = {std::string("left_") + entry.name, std::string("right_") + entry.name};
    } else {
      names = {entry.name};
    }
    for (const std::string& name : names) {
      if (groups[model::body_group(name)]) out[name] = entry.spacing * scale;
    }
  };
  for (const Spacing& entry : kV1Spacings) {
    if (version == model::MimoVersion::kV2 && std::string_view(entry.name) == "fingers") continue;
    add(entry);
  }
  if (version == model::MimoVersion::kV2) {
    for (const Spacing& entry : kV2Extras) add(entry);
  }
  return out;
}

Touch::Touch(const mjModel* m, const TouchOptions& options)
    : function_(options.function), response_(options.response) {
  body_table_.assign(m->nbody, -1);
  geom_table_.assign(m->ngeom, -1);

  // Resolve body names; tables go in ascending body id.
  std::vector<std::pair<int, double>> chosen;
  for (const auto& [name, spacing] : options.body_scales) {
    const int id = mj_name2id(m, mjOBJ_BODY, name.c_str());
    if (id < 0) throw UserError("touch: the model has no body named '" + name + "'");
    if (!(spacing > 0) || !std::isfinite(spacing)) {
      throw UserError("touch: sensor spacing of body '" + name +
                      "' must be a positive number, got " + std::to_string(spacing));
    }
    chosen.emplace_back(id, spacing);
  }
  std::sort(chosen.begin(), chosen.end());

  for (const auto& [body, spacing] : chosen) {
    // Sensor points of every collision geom, in the body frame.
    std::vector<GeomSensors> geoms;
    const int adr = m->body_geomadr[body];
    for (int g = adr; g >= 0 && g < adr + m->body_geomnum[body]; ++g) {
      if (m->geom_contype[g] == 0 && m->geom_conaffinity[g] == 0) continue;
      GeomSensors gs;
      gs.id = g;
      gs.shape.type = static_cast<mjtGeom>(m->geom_type[g]);
      std::copy_n(m->geom_size + 3 * g, 3, gs.shape.size.begin());
      gs.shape.rbound = m->geom_rbound[g];
      mju_quat2Mat(gs.pose.rot.data(), m->geom_quat + 4 * g);
      std::copy_n(m->geom_pos + 3 * g, 3, gs.pose.pos.begin());
      gs.single = single_point(gs.shape, spacing);
      for (const Point3& p : shape_points(gs.shape, spacing)) {
        gs.points.push_back(to_body(gs.pose, p));
      }
      geoms.push_back(std::move(gs));
    }

    // Keep the points that no other (non-single-point) geom of the body covers.
    BodyTable table;
    table.body = body;
    table.spacing = spacing;
    table.first = sensor_count();
    for (const GeomSensors& gs : geoms) {
      for (const Point3& p : gs.points) {
        bool hidden = false;
        for (const GeomSensors& other : geoms) {
          if (&other == &gs || other.single) continue;
          if (inside_shape(other.shape, to_geom(other.pose, p), kInsideTolerance)) {
            hidden = true;
            break;
          }
        }
        if (hidden) continue;
        positions_.push_back(p);
        sensor_body_.push_back(body);
        sensor_geom_.push_back(gs.id);
      }
    }
    table.count = sensor_count() - table.first;
    build_grid(table);

    const int index = static_cast<int>(tables_.size());
    body_table_[body] = index;
    for (int g = adr; g >= 0 && g < adr + m->body_geomnum[body]; ++g) geom_table_[g] = index;
    tables_.push_back(table);
  }
}

Box Touch::space() const { return Box::unbounded({size()}, DType::kFloat32); }

std::vector<int> Touch::bodies() const {
  std::vector<int> out;
  for (const BodyTable& t : tables_) out.push_back(t.body);
  return out;
}

int Touch::sensors_on_body(int body_id) const {
  if (body_id < 0 || body_id >= static_cast<int>(body_table_.size())) return 0;
  const int t = body_table_[body_id];
  return t < 0 ? 0 : tables_[t].count;
}

int Touch::first_sensor(int body_id) const {
  if (body_id < 0 || body_id >= static_cast<int>(body_table_.size())) return -1;
  const int t = body_table_[body_id];
  return t < 0 ? -1 : tables_[t].first;
}

// Buckets the body's sensors into a uniform grid with cells of 2 × spacing (the spread radius),
// coarsened when that would give far more cells than sensors.
void Touch::build_grid(BodyTable& table) {
  table.cells_at = static_cast<int>(cell_start_.size());
  Point3 lo = {0, 0, 0}, hi = {0, 0, 0};
  for (int i = 0; i < table.count; ++i) {
    const Point3& p = positions_[table.first + i];
    for (int k = 0; k < 3; ++k) {
      lo[k] = i == 0 ? p[k] : std::min(lo[k], p[k]);
      hi[k] = i == 0 ? p[k] : std::max(hi[k], p[k]);
    }
  }
  table.origin = lo;
  table.cell = 2 * table.spacing;
  auto cells = [&] {
    double n = 1;
    for (int k = 0; k < 3; ++k) n *= std::floor((hi[k] - lo[k]) / table.cell) + 1;
    return n;
  };
  while (cells() > 8.0 * table.count + 64) table.cell *= 2;
  for (int k = 0; k < 3; ++k) table.dims[k] = static_cast<int>((hi[k] - lo[k]) / table.cell) + 1;

  // Counting sort of the sensors by cell.
  const int ncells = table.dims[0] * table.dims[1] * table.dims[2];
  std::vector<int> cell_of_sensor(table.count);
  std::vector<int> start(ncells + 1, 0);
  for (int i = 0; i < table.count; ++i) {
    const auto c = cell_of(table, positions_[table.first + i]);
    cell_of_sensor[i] = (c[0] * table.dims[1] + c[1]) * table.dims[2] + c[2];
    ++start[cell_of_sensor[i] + 1];
  }
  for (int c = 0; c < ncells; ++c) start[c + 1] += start[c];
  const int base = static_cast<int>(grid_sensor_.size());
  grid_sensor_.resize(base + table.count);
  grid_pos_.resize(base + table.count);
  std::vector<int> fill(start.begin(), start.end() - 1);
  for (int i = 0; i < table.count; ++i) {
    const int slot = base + fill[cell_of_sensor[i]]++;
    grid_sensor_[slot] = table.first + i;
    grid_pos_[slot] = positions_[table.first + i];
  }
  for (int c = 0; c <= ncells; ++c) cell_start_.push_back(base + start[c]);
}

// Grid cell holding q, clamped to the grid (q may lie outside it).
std::array<int, 3> Touch::cell_of(const BodyTable& table, const Point3& q) const {
  std::array<int, 3> c;
  for (int k = 0; k < 3; ++k) {
    const double t = std::floor((q[k] - table.origin[k]) / table.cell);
    // Written so that NaN (a diverged simulation) lands in cell 0.
    c[k] = t > 0 ? static_cast<int>(std::min(t, static_cast<double>(table.dims[k] - 1))) : 0;
  }
  return c;
}

// Closest sensor of the body to q: grid shells of growing radius around q's cell, stopping once
// no unvisited cell can hold anything closer. -1 only for a body without sensors.
int Touch::nearest(const BodyTable& table, const Point3& q) const {
  const std::array<int, 3> c = cell_of(table, q);
  const auto& dims = table.dims;
  int best = -1;
  double best_d2 = std::numeric_limits<double>::infinity();
  for (int k = 0;; ++k) {
    std::array<int, 3> lo, hi;
    for (int a = 0; a < 3; ++a) {
      lo[a] = c[a] - k;
      hi[a] = c[a] + k;
    }
    // Visit the cells of shell k (Chebyshev distance exactly k from c) inside the grid.
    for (int x = std::max(lo[0], 0); x <= std::min(hi[0], dims[0] - 1); ++x) {
      for (int y = std::max(lo[1], 0); y <= std::min(hi[1], dims[1] - 1); ++y) {
        const bool inner_xy = x != lo[0] && x != hi[0] && y != lo[1] && y != hi[1];
        const int step = inner_xy ? std::max(1, 2 * k) : 1;
        for (int z = lo[2]; z <= hi[2]; z += step) {
          if (z < 0 || z >= dims[2]) continue;
          const int cell = table.cells_at + (x * dims[1] + y) * dims[2] + z;
          for (int i = cell_start_[cell]; i < cell_start_[cell + 1]; ++i) {
            const double d2 = dist2(grid_pos_[i], q);
            if (d2 < best_d2) {
              best_d2 = d2;
              best = grid_sensor_[i];
            }
          }
        }
      }
    }
    // Lower bound on the distance to any cell outside the visited cube.
    bool covered = true;
    double bound = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
      if (lo[a] > 0) {
        covered = false;
        bound = std::min(bound, q[a] - (table.origin[a] + lo[a] * table.cell));
      }
      if (hi[a] < dims[a] - 1) {
        covered = false;
        bound = std::min(bound, table.origin[a] + (hi[a] + 1) * table.cell - q[a]);
      }
    }
    if (covered) break;
    if (best >= 0 && bound > 0 && best_d2 <= bound * bound) break;
  }
  return best;
}

void Touch::add_value(const Hit& hit, double weight, int sensor, float* out) const {
  if (function_ == TouchFunction::kNormal) {
    out[sensor] += static_cast<float>(hit.value[0] * weight);
    return;
  }
  for (int k = 0; k < 3; ++k) out[3 * sensor + k] += static_cast<float>(hit.value[k] * weight);
}

// Applies one contact's value to a body's sensors. spread_linear: every sensor closer than 2s
// gets weight (2s - d)/(2s), normalised to sum 1 so the force is conserved. Where no sensor is
// that close (contact on a hidden patch), the whole force goes to the nearest sensor instead of
// being dropped as in the reference, so no touch is lost.
void Touch::deposit(const BodyTable& table, const Hit& hit, float* out) const {
  if (table.count == 0) return;
  if (response_ == TouchResponse::kSpreadLinear) {
    const double radius = 2 * table.spacing;
    const auto& p = hit.pos;
    const std::array<int, 3> lo = cell_of(table, {p[0] - radius, p[1] - radius, p[2] - radius});
    const std::array<int, 3> hi = cell_of(table, {p[0] + radius, p[1] + radius, p[2] + radius});
    // Two passes over the same cells: total weight, then the normalised deposits.
    auto visit = [&](auto&& use) {
      for (int x = lo[0]; x <= hi[0]; ++x) {
        for (int y = lo[1]; y <= hi[1]; ++y) {
          const int row = table.cells_at + (x * table.dims[1] + y) * table.dims[2];
          for (int i = cell_start_[row + lo[2]]; i < cell_start_[row + hi[2] + 1]; ++i) {
            const double d2 = dist2(grid_pos_[i], hit.pos);
            if (d2 < radius * radius) use(grid_sensor_[i], (radius - std::sqrt(d2)) / radius);
          }
        }
      }
    };
    double total = 0;
    visit([&](int, double w) { total += w; });
    if (total > 0) {
      visit([&](int sensor, double w) { add_value(hit, w / total, sensor, out); });
      return;
    }
  }
  const int closest = nearest(table, hit.pos);
  if (closest >= 0) add_value(hit, 1.0, closest, out);
}

void Touch::read(const mjModel* m, const mjData* d, std::span<float> out) const {
  if (static_cast<int>(out.size()) != size()) {
    throw std::invalid_argument("Touch::read: output has the wrong size");
  }
  std::fill(out.begin(), out.end(), 0.0f);
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& con = d->contact[i];
    const int t1 = geom_table_[con.geom1];
    const int t2 = geom_table_[con.geom2];
    if (t1 < 0 && t2 < 0) continue;
    mjtNum f[6];
    mj_contactForce(m, d, i, f);
    if (std::abs(f[0]) < kMinNormalForce) continue;
    // World force on geom2 (frame rows: normal from geom1 to geom2, tangent 1, tangent 2).
    mjtNum world[3];
    mju_mulMatTVec(world, con.frame, f, 3, 3);
    for (int side = 0; side < 2; ++side) {
      const int t = side == 0 ? t1 : t2;
      if (t < 0) continue;
      const BodyTable& table = tables_[t];
      // geom1's body feels the opposite force; the normal into the sensing body flips likewise.
      const double sign = side == 0 ? -1.0 : 1.0;
      const mjtNum* xpos = d->xpos + 3 * table.body;
      const mjtNum* xmat = d->xmat + 9 * table.body;
      // Contact point moved from the midpoint onto this body's surface when penetrating.
      const double shift = con.dist < 0 ? sign * con.dist / 2 : 0;
      mjtNum rel[3], local[3];
      for (int k = 0; k < 3; ++k) rel[k] = con.pos[k] + shift * con.frame[k] - xpos[k];
      mju_mulMatTVec(local, xmat, rel, 3, 3);
      Hit hit;
      hit.pos = {local[0], local[1], local[2]};
      mjtNum force[3] = {sign * world[0], sign * world[1], sign * world[2]};
      switch (function_) {
        case TouchFunction::kNormal:
          hit.value = {std::abs(f[0]), 0, 0};
          break;
        case TouchFunction::kForceVectorGlobal:
          hit.value = {force[0], force[1], force[2]};
          break;
        case TouchFunction::kForceVector: {
          mjtNum body_force[3];
          mju_mulMatTVec(body_force, xmat, force, 3, 3);
          hit.value = {body_force[0], body_force[1], body_force[2]};
          break;
        }
      }
      deposit(table, hit, out.data());
    }
  }
}

}  // namespace cradle::senses

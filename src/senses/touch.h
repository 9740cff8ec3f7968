// Touch: MIMo's skin as thousands of sensor points on the collision geoms of chosen bodies
// (mimo_core.md §4.4). Contact forces are mapped onto the sensor points of the touched body.
//
// Force convention: every output is the force acting ON the sensing body. Its normal component
// therefore points into the sensing surface: for a body resting on the floor the force is upward,
// i.e. opposite to the outward surface normal at the contact. kNormal outputs the normal force
// magnitude (>= 0), one value per sensor; kForceVector and kForceVectorGlobal output 3 values per
// sensor, in the body frame and the world frame respectively.
#pragma once

#include <mujoco/mujoco.h>

#include <array>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "core/config.h"
#include "core/groups.h"
#include "core/spaces.h"
#include "model/infant.h"
#include "senses/touch_mesh.h"

namespace cradle::senses {

// Per-body sensor spacing (m) of the reference defaults for `version` (v1: DEFAULT_TOUCH_PARAMS,
// v2: DEFAULT_TOUCH_PARAMS_V2 with its own finger segments and big toes), restricted to the
// enabled groups and multiplied by `scale`.
std::map<std::string, double> default_touch_scales(model::MimoVersion version,
                                                   const GroupFlags& groups, double scale);

struct TouchOptions {
  std::map<std::string, double> body_scales;  // body name -> spacing (m); others have no sensors
  TouchFunction function = TouchFunction::kForceVector;
  TouchResponse response = TouchResponse::kSpreadLinear;
};

// Built once per compiled model, then immutable: one Touch may be shared by many envs and threads.
// read() writes only to its output and allocates nothing.
class Touch {
 public:
  // Generates the sensors. Throws UserError for an unknown body name or a spacing <= 0.
  Touch(const mjModel* m, const TouchOptions& options);

  int sensor_count() const { return static_cast<int>(positions_.size()); }
  int values_per_sensor() const { return function_ == TouchFunction::kNormal ? 1 : 3; }
  int size() const { return sensor_count() * values_per_sensor(); }
  Box space() const;  // float32, shape {size()}, unbounded
  TouchFunction function() const { return function_; }
  TouchResponse response() const { return response_; }

  // Zeroes `out` (size() floats) and accumulates this step's contact forces onto the sensors.
  // `m` must be the model the Touch was built from (or an identical copy).
  void read(const mjModel* m, const mjData* d, std::span<float> out) const;

  // Sensor positions in their body's frame, in output order.
  std::span<const Point3> positions() const { return positions_; }
  // Body id and geom id of each sensor, in output order.
  std::span<const int> sensor_bodies() const { return sensor_body_; }
  std::span<const int> sensor_geoms() const { return sensor_geom_; }
  // Sensing body ids in output order (ascending id); a listed body may have no sensors.
  std::vector<int> bodies() const;
  // Number of sensors on a body (0 for bodies without touch).
  int sensors_on_body(int body_id) const;
  // Index of a body's first sensor in output order (-1 for bodies without touch).
  int first_sensor(int body_id) const;

 private:
  // One sensing body: its sensors [first, first + count) and a uniform grid over them.
  struct BodyTable {
    int body = -1;
    double spacing = 0;
    int first = 0;
    int count = 0;
    std::array<double, 3> origin{0, 0, 0};  // grid corner, body frame
    double cell = 1;                        // grid cell edge (m)
    std::array<int, 3> dims{1, 1, 1};       // cells per axis
    int cells_at = 0;                       // offset of this body's cells in cell_start_
  };
  // Where the force of one contact lands, for one sensing body.
  struct Hit {
    Point3 pos;                   // contact point, body frame
    std::array<double, 3> value;  // output value (first entry only for kNormal)
  };

  void build_grid(BodyTable& table);
  int nearest(const BodyTable& table, const Point3& q) const;
  void deposit(const BodyTable& table, const Hit& hit, float* out) const;
  void add_value(const Hit& hit, double weight, int sensor, float* out) const;
  std::array<int, 3> cell_of(const BodyTable& table, const Point3& q) const;

  TouchFunction function_;
  TouchResponse response_;
  std::vector<BodyTable> tables_;  // ascending body id
  std::vector<int> body_table_;    // body id -> index in tables_, -1 if not sensing
  std::vector<int> geom_table_;    // geom id -> index in tables_ of its body, -1 if not sensing
  std::vector<Point3> positions_;  // output order
  std::vector<int> sensor_body_;   // output order
  std::vector<int> sensor_geom_;   // output order
  // Grid contents: per body, cell c spans grid_sensor_[cell_start_[cells_at + c] ...
  // cell_start_[cells_at + c + 1]); grid_pos_ holds the same sensors' positions alongside.
  std::vector<int> cell_start_;
  std::vector<int> grid_sensor_;
  std::vector<Point3> grid_pos_;
};

}  // namespace cradle::senses

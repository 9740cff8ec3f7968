// Touch: sensor generation per primitive (hand-computed counts from mimo_core.md §4.4), overlap
// removal, force mapping (nearest / spread_linear, conservation, frames, sign), MIMo's reference
// counts, and the cost of read() next to mj_step.
#include "senses/touch.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <random>
#include <set>
#include <string>
#include <string_view>
#include <thread>
#include <vector>

#include "core/config.h"
#include "core/error.h"
#include "fixture.h"
#include "model/infant.h"
#include "scene/compose.h"

namespace cradle::senses {
namespace {

namespace fs = std::filesystem;

struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
using DataPtr = std::unique_ptr<mjData, DataDeleter>;

// Compiles an inline MJCF model through a temporary file.
scene::ModelPtr load_xml(const std::string& xml) {
  const fs::path file =
      fs::temp_directory_path() / ("cradle_touch_test_" + std::to_string(::getpid()) + ".xml");
  std::ofstream(file) << xml;
  char error[1000] = "";
  mjModel* m = mj_loadXML(file.string().c_str(), nullptr, error, sizeof(error));
  fs::remove(file);
  EXPECT_NE(m, nullptr) << error;
  return scene::ModelPtr(m);
}

int body_id(const mjModel* m, const char* name) { return mj_name2id(m, mjOBJ_BODY, name); }

// Number of points the generator puts on one primitive.
int count(mjtGeom type, std::array<double, 3> size, double spacing) {
  return static_cast<int>(shape_points({type, size, 0}, spacing).size());
}

// ---------------------------------------------------------------------------------------------
// Generation: counts from the §4.4 formulas, worked by hand.

TEST(TouchMesh, BoxFaceGrid) {
  // n = ceil(0.2/0.05) = 4 per axis: 4^3 - 2^3 = 56 surface nodes.
  EXPECT_EQ(count(mjGEOM_BOX, {0.1, 0.1, 0.1}, 0.05), 56);
  // n = (4, 2, 2): every node is on a face.
  EXPECT_EQ(count(mjGEOM_BOX, {0.1, 0.03, 0.02}, 0.05), 16);
}

TEST(TouchMesh, SphereLatitudeRings) {
  // 7 rings at (i + 1/2) pi / 7; round(4 pi sin(theta)) = 3, 8, 11, 13, 11, 8, 3.
  EXPECT_EQ(count(mjGEOM_SPHERE, {0.1, 0, 0}, 0.05), 57);
}

TEST(TouchMesh, CapsuleRingsAndCaps) {
  // 7 around; 5 side rings = 35; each cap: pole + ring of ceil(2 pi sin 45deg) = 5, its equator
  // merges with the end ring: 35 + 2 * 6 = 47.
  EXPECT_EQ(count(mjGEOM_CAPSULE, {0.05, 0.1, 0}, 0.05), 47);
}

TEST(TouchMesh, CylinderSideAndCaps) {
  // 5 side rings of 7 = 35; caps have radii {0, R}: the centre point is new, the rim merges.
  EXPECT_EQ(count(mjGEOM_CYLINDER, {0.05, 0.1, 0}, 0.05), 37);
}

TEST(TouchMesh, EllipsoidLiesOnItsSurface) {
  const Shape shape{mjGEOM_ELLIPSOID, {0.1, 0.05, 0.03}, 0};
  const auto points = shape_points(shape, 0.05);
  EXPECT_EQ(points.size(), 57u);  // the sphere scheme at the largest semi-axis
  for (const Point3& p : points) {
    const double q = std::pow(p[0] / 0.1, 2) + std::pow(p[1] / 0.05, 2) + std::pow(p[2] / 0.03, 2);
    EXPECT_NEAR(q, 1.0, 1e-12);
  }
}

TEST(TouchMesh, SinglePointWhenTooCoarse) {
  EXPECT_EQ(count(mjGEOM_SPHERE, {0.01, 0, 0}, 0.05), 1);       // r > R
  EXPECT_EQ(count(mjGEOM_BOX, {0.03, 0.01, 0.02}, 0.05), 1);    // 0.75 r > max half size
  EXPECT_EQ(count(mjGEOM_BOX, {0.04, 0.01, 0.02}, 0.05), 8);    // 0.75 r < 0.04: corners
  EXPECT_EQ(count(mjGEOM_CAPSULE, {0.005, 0.1, 0}, 0.05), 1);   // < 3 points around
  EXPECT_EQ(count(mjGEOM_CYLINDER, {0.05, 0.01, 0}, 0.05), 1);  // < 2 side segments
  EXPECT_EQ(count(mjGEOM_CYLINDER, {0.02, 0.1, 0}, 0.05), 1);   // round(R/r) + 1 == 1
  EXPECT_TRUE(shape_points({mjGEOM_PLANE, {1, 1, 1}, 0}, 0.05).empty());
  const auto single = shape_points({mjGEOM_SPHERE, {0.01, 0, 0}, 0}, 0.05);
  EXPECT_EQ(single[0], (Point3{0, 0, 0}));
}

TEST(TouchMesh, PointsLieOnTheSurfaceWithoutDuplicates) {
  for (const Shape& shape :
       {Shape{mjGEOM_CAPSULE, {0.02, 0.03, 0}, 0}, Shape{mjGEOM_CYLINDER, {0.02, 0.03, 0}, 0},
        Shape{mjGEOM_SPHERE, {0.02, 0, 0}, 0}, Shape{mjGEOM_BOX, {0.02, 0.01, 0.03}, 0}}) {
    const auto points = shape_points(shape, 0.004);
    for (size_t i = 0; i < points.size(); ++i) {
      EXPECT_FALSE(inside_shape(shape, points[i], 1e-9)) << "type " << shape.type;
      for (size_t j = 0; j < i; ++j) {
        const double d = std::hypot(points[i][0] - points[j][0], points[i][1] - points[j][1],
                                    points[i][2] - points[j][2]);
        EXPECT_GT(d, 1e-6);
      }
    }
  }
}

TEST(TouchMesh, InsideTests) {
  const Shape capsule{mjGEOM_CAPSULE, {0.1, 0.2, 0}, 0};
  EXPECT_TRUE(inside_shape(capsule, {0, 0, 0.29}, 1e-9));
  EXPECT_FALSE(inside_shape(capsule, {0, 0, 0.31}, 1e-9));
  EXPECT_FALSE(inside_shape(capsule, {0.1, 0, 0}, 1e-9));  // on the surface: not inside
  const Shape cylinder{mjGEOM_CYLINDER, {0.1, 0.2, 0}, 0};
  EXPECT_TRUE(inside_shape(cylinder, {0.09, 0, 0.19}, 1e-9));
  EXPECT_FALSE(inside_shape(cylinder, {0.08, 0.07, 0}, 1e-9));
  const Shape box{mjGEOM_BOX, {0.1, 0.2, 0.3}, 0};
  EXPECT_TRUE(inside_shape(box, {0.09, -0.19, 0.29}, 1e-9));
  EXPECT_FALSE(inside_shape(box, {0.1, 0, 0}, 1e-9));
}

// ---------------------------------------------------------------------------------------------
// Touch on small models.

constexpr const char* kPrimitives = R"(
<mujoco>
  <worldbody>
    <body name="box" pos="0 0 1"><geom type="box" size=".1 .1 .1"/></body>
    <body name="sphere" pos="1 0 1"><geom type="sphere" size=".1"/></body>
    <body name="capsule" pos="2 0 1"><geom type="capsule" size=".05 .1"/></body>
    <body name="cylinder" pos="3 0 1"><geom type="cylinder" size=".05 .1"/></body>
    <body name="ghost" pos="4 0 1"><geom type="sphere" size=".1" contype="0" conaffinity="0"/></body>
    <body name="pair" pos="5 0 1">
      <geom type="sphere" size=".1" pos="-.05 0 0"/>
      <geom type="sphere" size=".1" pos=".05 0 0" euler="0 90 0"/>
    </body>
    <body name="dot" pos="6 0 1">
      <geom type="sphere" size=".1"/>
      <geom type="sphere" size=".01" pos=".095 0 0"/>
    </body>
  </worldbody>
</mujoco>)";

TEST(Touch, CountsPerBodyAndOrder) {
  const auto m = load_xml(kPrimitives);
  TouchOptions options;
  for (const char* name : {"box", "sphere", "capsule", "cylinder", "ghost"}) {
    options.body_scales[name] = 0.05;
  }
  const Touch touch(m.get(), options);
  EXPECT_EQ(touch.sensors_on_body(body_id(m.get(), "box")), 56);
  EXPECT_EQ(touch.sensors_on_body(body_id(m.get(), "sphere")), 57);
  EXPECT_EQ(touch.sensors_on_body(body_id(m.get(), "capsule")), 47);
  EXPECT_EQ(touch.sensors_on_body(body_id(m.get(), "cylinder")), 37);
  EXPECT_EQ(touch.sensors_on_body(body_id(m.get(), "ghost")), 0);  // no collision geom
  EXPECT_EQ(touch.sensors_on_body(body_id(m.get(), "pair")), 0);   // not listed
  EXPECT_EQ(touch.sensor_count(), 56 + 57 + 47 + 37);
  EXPECT_EQ(touch.size(), 3 * touch.sensor_count());
  EXPECT_EQ(touch.space(), Box::unbounded({touch.size()}, DType::kFloat32));
  // Bodies in ascending id; sensors grouped by body in that order.
  const std::vector<int> bodies = touch.bodies();
  EXPECT_TRUE(std::is_sorted(bodies.begin(), bodies.end()));
  EXPECT_EQ(bodies.size(), 5u);
  const auto owner = touch.sensor_bodies();
  EXPECT_TRUE(std::is_sorted(owner.begin(), owner.end()));
  EXPECT_EQ(touch.first_sensor(body_id(m.get(), "sphere")), 56);
  // Positions are in the body frame: the box sensors span its half sizes.
  for (int i = 0; i < 56; ++i) {
    const Point3& p = touch.positions()[i];
    EXPECT_NEAR(std::max({std::abs(p[0]), std::abs(p[1]), std::abs(p[2])}), 0.1, 1e-12);
  }
}

TEST(Touch, UnknownBodyOrBadSpacingIsAUserError) {
  const auto m = load_xml(kPrimitives);
  EXPECT_THROW(Touch(m.get(), TouchOptions{.body_scales = {{"nobody", 0.05}}}), UserError);
  EXPECT_THROW(Touch(m.get(), TouchOptions{.body_scales = {{"box", 0.0}}}), UserError);
}

TEST(Touch, PointsInsideAnotherGeomOfTheBodyAreNotSensors) {
  const auto m = load_xml(kPrimitives);
  const Touch touch(m.get(), TouchOptions{.body_scales = {{"pair", 0.05}, {"dot", 0.05}}});
  // Expected: each sphere's 57 points minus those strictly inside the other sphere.
  const auto sphere = shape_points({mjGEOM_SPHERE, {0.1, 0, 0}, 0}, 0.05);
  int outside = 0;
  for (const Point3& p : sphere) {
    if (std::hypot(p[0] - 0.1, p[1], p[2]) >= 0.1 - 1e-9) ++outside;  // -0.05 vs +0.05 centres
  }
  const int pair = body_id(m.get(), "pair");
  EXPECT_LT(outside, 57);
  // The rotated second sphere has different points but by symmetry hides the same count.
  const int total = touch.sensors_on_body(pair);
  EXPECT_GT(total, outside);
  EXPECT_LT(total, 2 * 57);
  for (int i = 0; i < touch.sensor_count(); ++i) {
    if (touch.sensor_bodies()[i] != pair) continue;
    const Point3& p = touch.positions()[i];
    const bool first = touch.sensor_geoms()[i] == m->body_geomadr[pair];
    const double other_x = first ? 0.05 : -0.05;
    EXPECT_GE(std::hypot(p[0] - other_x, p[1], p[2]), 0.1 - 1e-9);
  }
  // A single-point geom hides nothing, and its own point inside the big sphere is dropped.
  EXPECT_EQ(touch.sensors_on_body(body_id(m.get(), "dot")), 57);
}

// A free ball resting under gravity on a tilted static slab.
constexpr const char* kBallOnSlab = R"(
<mujoco>
  <option timestep="0.002"/>
  <worldbody>
    <body name="slab" pos="0.01 -0.02 0" euler="0 0 30">
      <geom type="box" size=".2 .2 .05"/>
    </body>
    <body name="ball" pos="0.013 0.004 0.11">
      <freejoint/>
      <geom type="sphere" size=".05" mass="0.5"/>
    </body>
  </worldbody>
</mujoco>)";

struct Resting {
  scene::ModelPtr m;
  DataPtr d;
};

Resting settle() {
  Resting r{load_xml(kBallOnSlab), nullptr};
  r.d.reset(mj_makeData(r.m.get()));
  for (int i = 0; i < 1000; ++i) mj_step(r.m.get(), r.d.get());
  return r;
}

// Sum of one body's sensor values (3 per sensor).
std::array<double, 3> body_sum(const Touch& touch, int body, const std::vector<float>& out) {
  std::array<double, 3> sum{0, 0, 0};
  for (int i = 0; i < touch.sensor_count(); ++i) {
    if (touch.sensor_bodies()[i] != body) continue;
    for (int k = 0; k < 3; ++k) sum[k] += out[3 * i + k];
  }
  return sum;
}

// World contact force on `body`, summed straight from mj_contactForce.
std::array<double, 3> contact_force_on(const mjModel* m, const mjData* d, int body) {
  std::array<double, 3> sum{0, 0, 0};
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& c = d->contact[i];
    const int b1 = m->geom_bodyid[c.geom1], b2 = m->geom_bodyid[c.geom2];
    if (b1 != body && b2 != body) continue;
    mjtNum f[6], w[3];
    mj_contactForce(m, d, i, f);
    mju_mulMatTVec(w, c.frame, f, 3, 3);
    const double sign = b2 == body ? 1 : -1;
    for (int k = 0; k < 3; ++k) sum[k] += sign * w[k];
  }
  return sum;
}

int nonzero_sensors(const std::vector<float>& out, int width) {
  int n = 0;
  for (size_t i = 0; i < out.size(); i += width) {
    bool any = false;
    for (int k = 0; k < width; ++k) any = any || out[i + k] != 0;
    n += any;
  }
  return n;
}

TEST(Touch, SpreadLinearConservesTheForceAndLightsTheNearestSensors) {
  Resting r = settle();
  const mjModel* m = r.m.get();
  const mjData* d = r.d.get();
  ASSERT_EQ(d->ncon, 1);
  const int slab = body_id(m, "slab"), ball = body_id(m, "ball");
  const Touch touch(m, TouchOptions{.body_scales = {{"slab", 0.02}, {"ball", 0.01}},
                                    .function = TouchFunction::kForceVectorGlobal});
  std::vector<float> out(touch.size());
  touch.read(m, d, out);

  const double weight = 0.5 * 9.81;
  for (int body : {slab, ball}) {
    const auto want = contact_force_on(m, d, body);
    const auto got = body_sum(touch, body, out);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], want[k], 0.01 * weight) << body << " " << k;
  }
  // Force on the ball is up (into its bottom surface), on the slab down, both ~ m g.
  EXPECT_NEAR(body_sum(touch, ball, out)[2], weight, 0.01 * weight);
  EXPECT_NEAR(body_sum(touch, slab, out)[2], -weight, 0.01 * weight);
  EXPECT_GT(nonzero_sensors(out, 3), 4);

  // The strongest slab sensor is the one closest to the contact point (on the slab surface).
  const mjContact& c = d->contact[0];
  mjtNum rel[3], local[3];
  for (int k = 0; k < 3; ++k) rel[k] = c.pos[k] - d->xpos[3 * slab + k];
  mju_mulMatTVec(local, d->xmat + 9 * slab, rel, 3, 3);
  int closest = -1, strongest = -1;
  double best_d = 1e9, best_f = -1;
  for (int i = 0; i < touch.sensor_count(); ++i) {
    if (touch.sensor_bodies()[i] != slab) continue;
    const Point3& p = touch.positions()[i];
    const double dist = std::hypot(p[0] - local[0], p[1] - local[1], p[2] - local[2]);
    const double f = std::hypot(out[3 * i], out[3 * i + 1], out[3 * i + 2]);
    if (dist < best_d) best_d = dist, closest = i;
    if (f > best_f) best_f = f, strongest = i;
  }
  EXPECT_EQ(strongest, closest);
  EXPECT_LT(best_d, 0.02);
}

TEST(Touch, NearestPutsTheWholeForceOnOneSensor) {
  Resting r = settle();
  const mjModel* m = r.m.get();
  const Touch touch(m, TouchOptions{.body_scales = {{"slab", 0.02}},
                                    .function = TouchFunction::kForceVectorGlobal,
                                    .response = TouchResponse::kNearest});
  std::vector<float> out(touch.size());
  touch.read(m, r.d.get(), out);
  EXPECT_EQ(nonzero_sensors(out, 3), 1);
  const auto want = contact_force_on(m, r.d.get(), body_id(m, "slab"));
  const auto got = body_sum(touch, body_id(m, "slab"), out);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(got[k], want[k], 1e-4);
}

TEST(Touch, NormalIsOneNonNegativeValuePerSensor) {
  Resting r = settle();
  const mjModel* m = r.m.get();
  const Touch touch(m, TouchOptions{.body_scales = {{"slab", 0.02}, {"ball", 0.01}},
                                    .function = TouchFunction::kNormal});
  EXPECT_EQ(touch.values_per_sensor(), 1);
  EXPECT_EQ(touch.size(), touch.sensor_count());
  std::vector<float> out(touch.size());
  touch.read(m, r.d.get(), out);
  mjtNum f[6];
  mj_contactForce(m, r.d.get(), 0, f);
  double slab_sum = 0, ball_sum = 0;
  for (int i = 0; i < touch.sensor_count(); ++i) {
    EXPECT_GE(out[i], 0.0f);
    (touch.sensor_bodies()[i] == body_id(m, "slab") ? slab_sum : ball_sum) += out[i];
  }
  EXPECT_NEAR(slab_sum, f[0], 1e-4 * f[0]);
  EXPECT_NEAR(ball_sum, f[0], 1e-4 * f[0]);
  EXPECT_NEAR(f[0], 0.5 * 9.81, 0.05);
}

TEST(Touch, ForceVectorIsTheGlobalForceInTheBodyFrame) {
  Resting r = settle();
  const mjModel* m = r.m.get();
  const mjData* d = r.d.get();
  const TouchOptions global{.body_scales = {{"slab", 0.02}},
                            .function = TouchFunction::kForceVectorGlobal};
  TouchOptions local = global;
  local.function = TouchFunction::kForceVector;
  const Touch tg(m, global), tl(m, local);
  std::vector<float> og(tg.size()), ol(tl.size());
  tg.read(m, d, og);
  tl.read(m, d, ol);
  const mjtNum* xmat = d->xmat + 9 * body_id(m, "slab");
  for (int i = 0; i < tg.sensor_count(); ++i) {
    const mjtNum w[3] = {og[3 * i], og[3 * i + 1], og[3 * i + 2]};
    mjtNum b[3];
    mju_mulMatTVec(b, xmat, w, 3, 3);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(ol[3 * i + k], b[k], 1e-5);
  }
  // The slab's top face normal is its local +z: the force on it points into it (-z).
  EXPECT_LT(body_sum(tl, body_id(m, "slab"), ol)[2], 0.0);
}

TEST(Touch, ReadIsSafeFromManyThreads) {
  Resting r = settle();
  const mjModel* m = r.m.get();
  const Touch touch(m, TouchOptions{.body_scales = {{"slab", 0.02}, {"ball", 0.01}}});
  std::vector<float> want(touch.size());
  touch.read(m, r.d.get(), want);
  std::vector<std::vector<float>> outs(4, std::vector<float>(touch.size()));
  std::vector<std::thread> threads;
  for (auto& out : outs) {
    threads.emplace_back([&] {
      for (int i = 0; i < 200; ++i) touch.read(m, r.d.get(), out);
    });
  }
  for (auto& t : threads) t.join();
  for (const auto& out : outs) EXPECT_EQ(out, want);
}

// ---------------------------------------------------------------------------------------------
// MIMo.

using test::reference_config;

TEST(TouchScales, DefaultsFollowVersionAndGroups) {
  const auto v1 = default_touch_scales(model::MimoVersion::kV1, default_touch_groups(), 1.0);
  EXPECT_EQ(v1.size(), 20u);  // 4 trunk/head + 8 sided bodies x 2 (no eyes)
  EXPECT_DOUBLE_EQ(v1.at("right_fingers"), 0.002);
  EXPECT_DOUBLE_EQ(v1.at("head"), 0.013);
  EXPECT_FALSE(v1.contains("left_eye"));
  const auto v2 = default_touch_scales(model::MimoVersion::kV2, GroupFlags::all(true), 2.0);
  EXPECT_FALSE(v2.contains("left_fingers"));
  EXPECT_DOUBLE_EQ(v2.at("left_eye"), 2.0);
  EXPECT_DOUBLE_EQ(v2.at("right_thdistal"), 0.004);
  EXPECT_DOUBLE_EQ(v2.at("left_lfmetacarpal"), 0.014);
  EXPECT_DOUBLE_EQ(v2.at("right_big_toe"), 0.02);
  EXPECT_EQ(v2.size(), 4u + 8 * 2 + 17 * 2);  // v1 without fingers, + 17 sided v2 bodies
  GroupFlags only_head = GroupFlags::all(false);
  only_head[Group::kHead] = true;
  EXPECT_EQ(default_touch_scales(model::MimoVersion::kV2, only_head, 1.0).size(), 1u);
}

// Sensors per body at scale 1 (side prefix dropped; both sides equal); they match the per-body
// figures of mimo_core.md §4.4.
const std::map<std::string, int> kV1Counts = {
    {"hip", 119},      {"lower_body", 116}, {"upper_body", 160}, {"head", 404},
    {"upper_arm", 54}, {"lower_arm", 47},   {"hand", 160},       {"fingers", 1944},
    {"upper_leg", 82}, {"lower_leg", 34},   {"foot", 83},        {"toes", 38}};
const std::map<std::string, int> kV2Counts = {
    {"hip", 119},      {"lower_body", 116},  {"upper_body", 160}, {"head", 404},
    {"upper_arm", 54}, {"lower_arm", 47},    {"hand", 142},       {"upper_leg", 82},
    {"lower_leg", 34}, {"foot", 79},         {"toes", 33},        {"big_toe", 23},
    {"ffknuckle", 82}, {"ffmiddle", 64},     {"ffdistal", 166},   {"mfknuckle", 98},
    {"mfmiddle", 64},  {"mfdistal", 213},    {"rfknuckle", 82},   {"rfmiddle", 64},
    {"rfdistal", 166}, {"lfmetacarpal", 27}, {"lfknuckle", 82},   {"lfmiddle", 46},
    {"lfdistal", 146}, {"thbase", 120},      {"thhub", 87},       {"thdistal", 248}};

void expect_counts(const std::map<std::string, int>& counts,
                   const std::map<std::string, int>& want) {
  for (const auto& [name, n] : counts) {
    std::string_view base = name;
    for (std::string_view side : {"left_", "right_"}) {
      if (base.starts_with(side)) base.remove_prefix(side.size());
    }
    ASSERT_TRUE(want.contains(std::string(base))) << name;
    EXPECT_EQ(n, want.at(std::string(base))) << name;
  }
}

// Prints and returns the sensor count per body name.
std::map<std::string, int> counts_by_name(const mjModel* m, const Touch& touch) {
  std::map<std::string, int> out;
  for (int b : touch.bodies()) {
    out[mj_id2name(m, mjOBJ_BODY, b)] = touch.sensors_on_body(b);
    std::printf("  %-20s %5d\n", mj_id2name(m, mjOBJ_BODY, b), touch.sensors_on_body(b));
  }
  std::printf("  %-20s %5d\n", "total", touch.sensor_count());
  return out;
}

TEST(TouchMimo, V1ReferenceCounts) {
  const Config config = reference_config("config_selftouch.yml");
  const auto m = scene::compile_scene(scene::compose_scene(config));
  const auto scales = default_touch_scales(model::MimoVersion::kV1, config.touch_groups, 1.0);
  const Touch touch(m.get(), TouchOptions{.body_scales = scales});
  const auto counts = counts_by_name(m.get(), touch);
  EXPECT_EQ(counts.size(), scales.size());
  for (const auto& [name, n] : counts) EXPECT_GT(n, 0) << name;
  expect_counts(counts, kV1Counts);
  // The reference estimate 5,685 includes the two one-point eyes, off in this config.
  EXPECT_EQ(touch.sensor_count(), 5683);
  EXPECT_NEAR(touch.sensor_count(), 5685, 0.1 * 5685);
}

TEST(TouchMimo, V2ReferenceCounts) {
  const Config config = reference_config("config_handregard.yml");
  const auto m = scene::compile_scene(scene::compose_scene(config));
  GroupFlags groups = GroupFlags::all(true);
  groups[Group::kEyes] = false;
  const auto scales = default_touch_scales(model::MimoVersion::kV2, groups, 1.0);
  const Touch touch(m.get(), TouchOptions{.body_scales = scales});
  const auto counts = counts_by_name(m.get(), touch);
  EXPECT_EQ(counts.size(), scales.size());
  for (const auto& [name, n] : counts) EXPECT_GT(n, 0) << name;
  expect_counts(counts, kV2Counts);
  EXPECT_EQ(touch.sensor_count(), 5297);  // 5,299 with the eyes
  EXPECT_NEAR(touch.sensor_count(), 5299, 0.1 * 5299);
  // The v1 defaults name mitten-hand bodies that v2 lacks (babybench_layer.md §1, item 7).
  EXPECT_THROW(Touch(m.get(), TouchOptions{.body_scales = default_touch_scales(
                                               model::MimoVersion::kV1, groups, 1.0)}),
               UserError);
}

TEST(TouchMimo, LyingInTheCribTouchesTheBack) {
  const Config config = reference_config("config_selftouch.yml");
  const auto m = scene::compile_scene(scene::compose_scene(config));
  DataPtr d(mj_makeData(m.get()));
  const Touch touch(m.get(), TouchOptions{.body_scales = default_touch_scales(
                                              model::MimoVersion::kV1, config.touch_groups, 1.0)});
  for (int i = 0; i < 200; ++i) mj_step(m.get(), d.get());
  std::vector<float> out(touch.size());
  touch.read(m.get(), d.get(), out);
  std::map<std::string, int> active;
  for (int i = 0; i < touch.sensor_count(); ++i) {
    if (out[3 * i] != 0 || out[3 * i + 1] != 0 || out[3 * i + 2] != 0) {
      ++active[mj_id2name(m.get(), mjOBJ_BODY, touch.sensor_bodies()[i])];
    }
  }
  for (const auto& [name, n] : active) std::printf("  active %-16s %4d\n", name.c_str(), n);
  EXPECT_GT(active["upper_body"] + active["head"] + active["hip"] + active["lower_body"], 0);
}

// Straightforward re-statement of the mapping with linear scans over all sensors (no grid).
std::vector<double> brute_force_read(const mjModel* m, const mjData* d, const Touch& touch,
                                     const std::map<std::string, double>& scales) {
  const int width = touch.values_per_sensor();
  std::vector<double> out(touch.size(), 0.0);
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& c = d->contact[i];
    mjtNum f[6], world[3];
    mj_contactForce(m, d, i, f);
    if (std::abs(f[0]) < 1e-9) continue;
    mju_mulMatTVec(world, c.frame, f, 3, 3);
    for (int side = 0; side < 2; ++side) {
      const int body = m->geom_bodyid[side == 0 ? c.geom1 : c.geom2];
      if (touch.sensors_on_body(body) == 0) continue;
      const double sign = side == 0 ? -1 : 1;
      const double s = scales.at(mj_id2name(m, mjOBJ_BODY, body));
      mjtNum rel[3], p[3], force[3], value[3];
      for (int k = 0; k < 3; ++k) {
        rel[k] =
            c.pos[k] + (c.dist < 0 ? sign * c.dist / 2 * c.frame[k] : 0) - d->xpos[3 * body + k];
        force[k] = sign * world[k];
      }
      mju_mulMatTVec(p, d->xmat + 9 * body, rel, 3, 3);
      if (touch.function() == TouchFunction::kForceVector) {
        mju_mulMatTVec(value, d->xmat + 9 * body, force, 3, 3);
      } else {
        mju_copy3(value, force);
      }
      if (touch.function() == TouchFunction::kNormal) value[0] = std::abs(f[0]);
      std::vector<std::pair<int, double>> weights;
      int closest = -1;
      double closest_d = 1e300, total = 0;
      for (int j = 0; j < touch.sensor_count(); ++j) {
        if (touch.sensor_bodies()[j] != body) continue;
        const Point3& q = touch.positions()[j];
        const double dist = std::hypot(q[0] - p[0], q[1] - p[1], q[2] - p[2]);
        if (dist < closest_d) closest_d = dist, closest = j;
        if (touch.response() == TouchResponse::kSpreadLinear && dist < 2 * s) {
          weights.emplace_back(j, (2 * s - dist) / (2 * s));
          total += weights.back().second;
        }
      }
      if (weights.empty()) weights = {{closest, 1.0}}, total = 1;
      for (const auto& [j, w] : weights) {
        for (int k = 0; k < width; ++k) out[width * j + k] += value[k] * w / total;
      }
    }
  }
  return out;
}

// The grid-based read() matches the linear-scan mapping on MIMo's own contacts (random
// controls, self-touch crib), for every function and response.
TEST(TouchMimo, MatchesBruteForceOnRandomMotion) {
  const Config config = reference_config("config_selftouch.yml");
  const auto m = scene::compile_scene(scene::compose_scene(config));
  const auto scales = default_touch_scales(model::MimoVersion::kV1, config.touch_groups, 1.0);
  std::vector<Touch> touches;
  for (TouchFunction function :
       {TouchFunction::kNormal, TouchFunction::kForceVector, TouchFunction::kForceVectorGlobal}) {
    for (TouchResponse response : {TouchResponse::kNearest, TouchResponse::kSpreadLinear}) {
      touches.emplace_back(m.get(), TouchOptions{scales, function, response});
    }
  }
  DataPtr d(mj_makeData(m.get()));
  std::mt19937 rng(3);
  int checked = 0;
  std::set<int> touched;  // sensing bodies seen in contact
  for (int step = 0; step < 600; ++step) {
    if (step % 20 == 0) {
      for (int a = 0; a < m->nu; ++a) {
        const double lo = m->actuator_ctrlrange[2 * a], hi = m->actuator_ctrlrange[2 * a + 1];
        d->ctrl[a] = std::uniform_real_distribution<double>(lo, hi)(rng);
      }
    }
    mj_step(m.get(), d.get());
    if (step % 10 != 0) continue;
    for (int i = 0; i < d->ncon; ++i) {
      for (int g : {d->contact[i].geom1, d->contact[i].geom2}) {
        const int b = m->geom_bodyid[g];
        if (touches[0].sensors_on_body(b) > 0) touched.insert(b);
      }
    }
    for (const Touch& touch : touches) {
      std::vector<float> out(touch.size());
      touch.read(m.get(), d.get(), out);
      const std::vector<double> want = brute_force_read(m.get(), d.get(), touch, scales);
      for (size_t i = 0; i < out.size(); ++i) {
        ASSERT_NEAR(out[i], want[i], 1e-5 + 1e-5 * std::abs(want[i])) << "step " << step;
      }
      ++checked;
    }
  }
  EXPECT_EQ(checked, 60 * 6);
  std::printf("  %zu sensing bodies in contact:", touched.size());
  for (int b : touched) std::printf(" %s", mj_id2name(m.get(), mjOBJ_BODY, b));
  std::printf("\n");
  EXPECT_GE(touched.size(), 5u);
}

// read() next to mj_step on the self-touch crib scene with random controls.
TEST(TouchMimo, ReadCostNextToPhysics) {
  const Config config = reference_config("config_selftouch.yml");
  const auto m = scene::compile_scene(scene::compose_scene(config));
  DataPtr d(mj_makeData(m.get()));
  const Touch touch(m.get(), TouchOptions{.body_scales = default_touch_scales(
                                              model::MimoVersion::kV1, config.touch_groups, 1.0)});
  std::vector<float> out(touch.size());
  std::mt19937 rng(7);
  // This thread's CPU time: waiting for a core on a loaded machine inflates neither cost (with
  // wall-clock time one preemption inside a read could fail the bound).
  struct Clock {
    static std::chrono::nanoseconds now() {
      timespec t{};
      clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
      return std::chrono::seconds(t.tv_sec) + std::chrono::nanoseconds(t.tv_nsec);
    }
  };
  std::chrono::nanoseconds physics{}, sensing{};
  long contacts = 0;
  const int steps = 3000;
  for (int i = 0; i < steps; ++i) {
    if (i % 20 == 0) {
      for (int a = 0; a < m->nu; ++a) {
        const double lo = m->actuator_ctrlrange[2 * a], hi = m->actuator_ctrlrange[2 * a + 1];
        d->ctrl[a] = std::uniform_real_distribution<double>(lo, hi)(rng);
      }
    }
    const auto t0 = Clock::now();
    mj_step(m.get(), d.get());
    const auto t1 = Clock::now();
    touch.read(m.get(), d.get(), out);
    const auto t2 = Clock::now();
    physics += t1 - t0;
    sensing += t2 - t1;
    contacts += d->ncon;
  }
  const double step_us = std::chrono::duration<double, std::micro>(physics).count() / steps;
  const double read_us = std::chrono::duration<double, std::micro>(sensing).count() / steps;
  std::printf("  mj_step %.1f us, touch read %.2f us (%.1f %%), %.1f contacts/step, %d sensors\n",
              step_us, read_us, 100 * read_us / step_us, double(contacts) / steps,
              touch.sensor_count());
  // Loose bound (shared CI machines); the target is 10 %.
  EXPECT_LT(read_us, 0.3 * step_us);
}

}  // namespace
}  // namespace cradle::senses

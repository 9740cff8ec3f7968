// The infant tables compiled alone (no world): counts, masses, height and joint ranges against the
// reference values of mimo_core.md §1.1 and §1.3.
#include "model/infant.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <map>
#include <numbers>
#include <set>
#include <string>

#include "core/xml.h"
#include "model/mjcf.h"
#include "scene/summary.h"

namespace cradle::model {
namespace {

// The infant on a free joint at z = 0.4 with untextured stand-ins for its materials.
mjModel* compile_alone(const Infant& infant, const EmitOptions& options = {}) {
  const InfantXml x = emit_infant(infant, options);
  std::set<std::string> materials = {"skin"};
  for (const Body& b : infant.bodies) {
    for (const Geom& g : b.geoms) {
      if (!g.material.empty()) materials.insert(g.material);
    }
  }
  XmlWriter xml;
  xml.open("mujoco");
  xml.leaf("compiler", {{"angle", "degree"}, {"inertiafromgeom", "true"}});
  xml.leaf("size", {{"nuser_actuator", "3"}});
  xml.open("default").raw(x.defaults).close();
  xml.open("asset");
  for (const std::string& m : materials) xml.leaf("material", {{"name", m}});
  xml.close();
  xml.open("worldbody").open("body", {{"name", "mimo_location"}, {"pos", "0 0 0.4"}});
  xml.leaf("joint", {{"name", "mimo_location"}, {"type", "free"}});
  xml.raw(x.body).close().close();
  xml.open("contact").raw(x.contact).close();
  xml.open("tendon").raw(x.tendon).close();
  xml.open("sensor").raw(x.sensor).close();
  if (!x.actuator.empty()) xml.open("actuator").raw(x.actuator).close();
  xml.open("equality").raw(x.equality).close();
  xml.close();

  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  const std::string& text = xml.str();
  mj_makeEmptyFileVFS(vfs.get(), "infant.xml", static_cast<int>(text.size()));
  std::copy(text.begin(), text.end(), static_cast<char*>(vfs->filedata[0]));
  char error[1000] = "";
  mjModel* m = mj_loadXML("infant.xml", vfs.get(), error, sizeof(error));
  mj_deleteVFS(vfs.get());
  EXPECT_NE(m, nullptr) << error;
  return m;
}

double deg(double radians) { return radians * 180.0 / std::numbers::pi; }

struct Expected {
  int joints, actuators, torque_sensors, bodies, geoms, sensordata, equalities, tendons;
  double mass;
};

void check_counts(MimoVersion version, const Expected& e) {
  mjModel* m = compile_alone(make_mimo(version));
  ASSERT_NE(m, nullptr);
  const scene::ModelSummary s = scene::summarize(m);
  EXPECT_EQ(s.n_joints, e.joints);
  EXPECT_EQ(s.n_actuators, e.actuators);
  EXPECT_EQ(s.n_torque_sensors, e.torque_sensors);
  EXPECT_EQ(s.n_bodies, e.bodies);
  EXPECT_EQ(s.n_geoms, e.geoms);
  EXPECT_EQ(m->nsensordata, e.sensordata);
  EXPECT_EQ(m->neq, e.equalities);
  EXPECT_EQ(m->ntendon, e.tendons);
  EXPECT_EQ(m->nq, 7 + e.joints);
  EXPECT_EQ(m->nv, 6 + e.joints);
  EXPECT_NEAR(s.total_mass, e.mass, 0.005 * e.mass);
  EXPECT_NEAR(s.height, 0.778, 0.01 * 0.778);
  EXPECT_EQ(m->ncam, 2);
  mj_deleteModel(m);
}

TEST(Infant, V1CountsMassAndHeightMatchReference) {
  check_counts(MimoVersion::kV1, {47, 44, 21, 22, 36, 69, 47, 9, 10.90487});
}

TEST(Infant, V2CountsMassAndHeightMatchReference) {
  check_counts(MimoVersion::kV2, {91, 88, 53, 54, 74, 165, 91, 9, 10.89991});
}

// Reference joint ranges in degrees (mimo_core.md §1.3), compiled to radians by MuJoCo.
TEST(Infant, V1JointRangesMatchReferenceTable) {
  const std::map<std::string, std::pair<double, double>> expected = {
      {"hip_lean1", {-14, 14}},
      {"hip_rot1", {-18, 18}},
      {"hip_bend1", {-17, 30.5}},
      {"hip_lean2", {-27, 27}},
      {"hip_rot2", {-18, 18}},
      {"hip_bend2", {-17, 30.5}},
      {"head_swivel", {-111, 111}},
      {"head_tilt", {-70, 81}},
      {"head_tilt_side", {-70, 70}},
      {"left_eye_horizontal", {-45, 45}},
      {"left_eye_vertical", {-47, 33}},
      {"left_eye_torsional", {-8, 8}},
      {"right_eye_horizontal", {-45, 45}},
      {"right_eye_vertical", {-47, 33}},
      {"right_eye_torsional", {-8, 8}}};
  const std::map<std::string, std::pair<double, double>> per_side = {
      {"shoulder_horizontal", {-28, 118}},
      {"shoulder_ad_ab", {-84, 183}},
      {"shoulder_rotation", {-99, 67}},
      {"elbow", {-146, 5}},
      {"hand1", {-90, 90}},
      {"hand2", {-92, 86}},
      {"hand3", {-53, 48}},
      {"fingers", {-160, 8}},
      {"hip1", {-133, 20}},
      {"hip2", {-51, 17}},
      {"hip3", {-32, 41}},
      {"knee", {-145, 4}},
      {"foot1", {-63, 32}},
      {"foot2", {-33, 31}},
      {"foot3", {-20, 30}},
      {"toes", {-60, 80}}};
  std::map<std::string, std::pair<double, double>> all = expected;
  for (const auto& [joint, range] : per_side) {
    all["right_" + joint] = range;
    all["left_" + joint] = range;
  }
  ASSERT_EQ(all.size(), 47u);

  mjModel* m = compile_alone(make_mimo_v1());
  ASSERT_NE(m, nullptr);
  for (const auto& [joint, range] : all) {
    const int id = mj_name2id(m, mjOBJ_JOINT, ("robot:" + joint).c_str());
    ASSERT_GE(id, 0) << joint;
    EXPECT_NEAR(deg(m->jnt_range[2 * id]), range.first, 1e-9) << joint;
    EXPECT_NEAR(deg(m->jnt_range[2 * id + 1]), range.second, 1e-9) << joint;
    EXPECT_TRUE(m->jnt_limited[id]) << joint;
  }
  // A few radian values quoted by the spec.
  auto range_of = [&](const char* joint) {
    return m->jnt_range + 2 * mj_name2id(m, mjOBJ_JOINT, joint);
  };
  EXPECT_NEAR(range_of("robot:head_swivel")[1], 1.93732, 1e-5);
  EXPECT_NEAR(range_of("robot:right_elbow")[0], -2.54818, 1e-5);
  EXPECT_NEAR(range_of("robot:right_knee")[1], 0.06981, 1e-5);
  mj_deleteModel(m);
}

// Compiled qpos order after the free joint: trunk, head, eyes, right arm, left arm, legs.
TEST(Infant, V1JointOrderIsReferenceQposOrder) {
  mjModel* m = compile_alone(make_mimo_v1());
  ASSERT_NE(m, nullptr);
  const char* order[] = {"hip_lean1",      "hip_rot1",           "hip_bend1",   "hip_lean2",
                         "hip_rot2",       "hip_bend2",          "head_swivel", "head_tilt",
                         "head_tilt_side", "left_eye_horizontal"};
  for (int i = 0; i < 10; ++i) {
    EXPECT_STREQ(mj_id2name(m, mjOBJ_JOINT, i + 1), (std::string("robot:") + order[i]).c_str());
  }
  EXPECT_STREQ(mj_id2name(m, mjOBJ_JOINT, 16), "robot:right_shoulder_horizontal");
  EXPECT_STREQ(mj_id2name(m, mjOBJ_JOINT, 24), "robot:left_shoulder_horizontal");
  EXPECT_STREQ(mj_id2name(m, mjOBJ_JOINT, 32), "robot:right_hip1");
  EXPECT_STREQ(mj_id2name(m, mjOBJ_JOINT, 47), "robot:left_toes");
  // The shoulder axis 0 1 -4 is normalised by the compiler.
  const int sh = mj_name2id(m, mjOBJ_JOINT, "robot:right_shoulder_horizontal");
  EXPECT_NEAR(m->jnt_axis[3 * sh + 1], 0.2425, 1e-4);
  EXPECT_NEAR(m->jnt_axis[3 * sh + 2], -0.9701, 1e-4);
  mj_deleteModel(m);
}

// Actuators: asymmetric force ranges, gears and the muscle user triple reach the model.
TEST(Infant, V1ActuatorsCarryGearForceRangeAndUserValues) {
  mjModel* m = compile_alone(make_mimo_v1());
  ASSERT_NE(m, nullptr);
  ASSERT_EQ(m->nuser_actuator, 3);
  const int elbow = mj_name2id(m, mjOBJ_ACTUATOR, "act:right_elbow");
  ASSERT_GE(elbow, 0);
  EXPECT_DOUBLE_EQ(m->actuator_gear[6 * elbow], 3.6);
  EXPECT_DOUBLE_EQ(m->actuator_forcerange[2 * elbow], -1);
  EXPECT_DOUBLE_EQ(m->actuator_forcerange[2 * elbow + 1], .83);
  EXPECT_DOUBLE_EQ(m->actuator_user[3 * elbow + 1], 35.43);
  EXPECT_TRUE(m->actuator_forcelimited[elbow]);
  EXPECT_STREQ(mj_id2name(m, mjOBJ_ACTUATOR, 0), "act:hip_bend");
  const int bend = mj_name2id(m, mjOBJ_JOINT, "robot:hip_bend1");
  EXPECT_EQ(m->actuator_trnid[0], bend);
  mj_deleteModel(m);
}

// Disabled groups have no actuators; positional servos use radian targets within joint range.
TEST(Infant, ActuationGroupsAndPositionalServos) {
  EmitOptions options;
  options.actuation = ActuationModel::kPositional;
  options.act_groups[Group::kFeet] = false;
  options.act_groups[Group::kEyes] = false;
  mjModel* m = compile_alone(make_mimo_v1(), options);
  ASSERT_NE(m, nullptr);
  EXPECT_EQ(m->nu, 44 - 8 - 6);
  const int elbow = mj_name2id(m, mjOBJ_ACTUATOR, "act:left_elbow");
  ASSERT_GE(elbow, 0);
  EXPECT_EQ(m->actuator_biastype[elbow], mjBIAS_AFFINE);
  EXPECT_NEAR(m->actuator_ctrlrange[2 * elbow], -146 * std::numbers::pi / 180, 1e-9);
  EXPECT_NEAR(m->actuator_ctrlrange[2 * elbow + 1], 5 * std::numbers::pi / 180, 1e-9);
  EXPECT_DOUBLE_EQ(m->actuator_gainprm[mjNGAIN * elbow], kPositionalGainPerGear * 3.6);
  EXPECT_EQ(mj_name2id(m, mjOBJ_ACTUATOR, "act:left_toes"), -1);
  mj_deleteModel(m);
}

// Locks: one per joint, active only for the locked groups (and not where the scene pins a joint).
TEST(Infant, LocksActiveForLockedGroupsOnly) {
  EmitOptions options;
  options.lock_groups[Group::kEyes] = true;
  options.lock_groups[Group::kFeet] = true;
  options.scene_constrained_joints = {"left_foot1"};
  mjModel* m = compile_alone(make_mimo_v1(), options);
  ASSERT_NE(m, nullptr);
  int active = 0;
  for (int i = 0; i < m->neq; ++i) active += m->eq_active[i];
  EXPECT_EQ(active, 6 + 8 - 1);
  const int eye = mj_name2id(m, mjOBJ_EQUALITY, "robot:left_eye_vertical");
  ASSERT_GE(eye, 0);
  EXPECT_TRUE(m->eq_active[eye]);
  EXPECT_EQ(m->eq_obj1id[eye], mj_name2id(m, mjOBJ_JOINT, "robot:left_eye_vertical"));
  EXPECT_FALSE(m->eq_active[mj_name2id(m, mjOBJ_EQUALITY, "robot:left_foot1")]);
  EXPECT_FALSE(m->eq_active[mj_name2id(m, mjOBJ_EQUALITY, "robot:right_elbow")]);
  mj_deleteModel(m);
}

// Eye cameras: on the eye surface, looking along the head's +x in the zero pose.
TEST(Infant, EyeCamerasLookForward) {
  mjModel* m = compile_alone(make_mimo_v1());
  ASSERT_NE(m, nullptr);
  mjData* d = mj_makeData(m);
  mj_kinematics(m, d);
  mj_camlight(m, d);
  for (const char* name : {"eye_left", "eye_right"}) {
    const int cam = mj_name2id(m, mjOBJ_CAMERA, name);
    ASSERT_GE(cam, 0);
    EXPECT_DOUBLE_EQ(m->cam_fovy[cam], 60);
    const mjtNum* x = d->cam_xmat + 9 * cam;
    // Camera looks along its -z (third column negated) and has its +y (second column) up.
    EXPECT_NEAR(-x[2], 1, 1e-9) << name;
    EXPECT_NEAR(x[7], 1, 1e-9) << name;
    EXPECT_NEAR(d->cam_xpos[3 * cam], 0.0813, 1e-3);
    EXPECT_NEAR(d->cam_xpos[3 * cam + 2], 0.7694, 1e-3);
  }
  EXPECT_NEAR(d->cam_xpos[3 * mj_name2id(m, mjOBJ_CAMERA, "eye_left") + 1], 0.0245, 1e-6);
  mj_deleteData(d);
  mj_deleteModel(m);
}

TEST(Infant, BodyGroupsFollowBabyBench) {
  EXPECT_EQ(body_group("hip"), Group::kBody);
  EXPECT_EQ(body_group("upper_body"), Group::kBody);
  EXPECT_EQ(body_group("left_eye"), Group::kEyes);
  EXPECT_EQ(body_group("right_lower_arm"), Group::kArms);
  EXPECT_EQ(body_group("right_hand"), Group::kHands);
  EXPECT_EQ(body_group("left_fingers"), Group::kFingers);
  EXPECT_EQ(body_group("right_ffdistal"), Group::kFingers);
  EXPECT_EQ(body_group("left_big_toe"), Group::kFeet);
  EXPECT_EQ(body_group("right_upper_leg"), Group::kLegs);
}

}  // namespace
}  // namespace cradle::model

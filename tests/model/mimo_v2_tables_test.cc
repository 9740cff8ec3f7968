// Table-level facts of the MIMo v2 model (no MuJoCo needed): counts, masses, orders, mirroring.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "model/infant.h"

namespace cradle::model {
namespace {

const Body* find_body(const Infant& infant, const std::string& name) {
  for (const Body& b : infant.bodies) {
    if (b.name == name) return &b;
  }
  return nullptr;
}

const Joint* find_joint(const Infant& infant, const std::string& name) {
  for (const auto& [body, joint] : joints_in_order(infant)) {
    if (joint->name == name) return joint;
  }
  return nullptr;
}

std::vector<std::string> joint_names(const Infant& infant) {
  std::vector<std::string> names;
  for (const auto& [body, joint] : joints_in_order(infant)) names.push_back(joint->name);
  return names;
}

int geom_count(const Infant& infant) {
  int n = 0;
  for (const Body& b : infant.bodies) n += static_cast<int>(b.geoms.size());
  return n;
}

double total_mass(const Infant& infant) {
  double m = 0;
  for (const Body& b : infant.bodies) {
    for (const Geom& g : b.geoms) m += g.mass;
  }
  return m;
}

// Mass of a body and everything below it.
double subtree_mass(const Infant& infant, const std::string& root) {
  std::set<std::string> inside = {root};
  double m = 0;
  for (const Body& b : infant.bodies) {
    if (b.name != root && !inside.contains(b.parent)) continue;
    inside.insert(b.name);
    for (const Geom& g : b.geoms) m += g.mass;
  }
  return m;
}

void expect_vec(const Vec3& actual, const Vec3& expected) {
  for (int i = 0; i < 3; ++i) EXPECT_DOUBLE_EQ(actual[i], expected[i]) << "component " << i;
}

TEST(MimoV2Tables, GlobalCounts) {
  const Infant infant = make_mimo_v2();
  EXPECT_EQ(infant.version, MimoVersion::kV2);
  EXPECT_EQ(joint_count(infant), 91);
  EXPECT_EQ(infant.bodies.size(), 54u);
  EXPECT_EQ(geom_count(infant), 74);
  EXPECT_EQ(infant.actuators.size(), 88u);
  EXPECT_EQ(infant.torque_sensors.size(), 53u);
  int sites = 0;
  for (const Body& b : infant.bodies) sites += static_cast<int>(b.sites.size());
  EXPECT_EQ(sites, 55);
  EXPECT_EQ(infant.tendons.size(), 9u);
}

TEST(MimoV2Tables, Masses) {
  const Infant infant = make_mimo_v2();
  EXPECT_NEAR(total_mass(infant), 10.89991, 10.89991 * 0.005);
  EXPECT_NEAR(total_mass(infant), 10.89991, 1e-4);
  EXPECT_NEAR(subtree_mass(infant, "right_hand"), 0.067, 5e-4);
  EXPECT_NEAR(subtree_mass(infant, "left_hand"), subtree_mass(infant, "right_hand"), 1e-12);
  EXPECT_NEAR(subtree_mass(infant, "right_upper_arm"), 0.525, 5e-4);
  EXPECT_NEAR(subtree_mass(infant, "right_foot"), 0.122, 5e-4);
  EXPECT_NEAR(subtree_mass(infant, "left_upper_leg"), 1.382, 5e-4);
}

TEST(MimoV2Tables, ActuatorGroups) {
  const Infant infant = make_mimo_v2();
  std::map<Group, int> counts;
  for (const Actuator& a : infant.actuators) ++counts[a.group];
  EXPECT_EQ(counts[Group::kBody], 3);
  EXPECT_EQ(counts[Group::kHead], 3);
  EXPECT_EQ(counts[Group::kEyes], 6);
  EXPECT_EQ(counts[Group::kArms], 8);
  EXPECT_EQ(counts[Group::kHands], 6);
  EXPECT_EQ(counts[Group::kFingers], 44);
  EXPECT_EQ(counts[Group::kLegs], 8);
  EXPECT_EQ(counts[Group::kFeet], 10);
  // Groups come in BabyBench order, never interleaved.
  for (size_t i = 1; i < infant.actuators.size(); ++i) {
    EXPECT_LE(static_cast<int>(infant.actuators[i - 1].group),
              static_cast<int>(infant.actuators[i].group))
        << infant.actuators[i].name;
  }
}

TEST(MimoV2Tables, ActuatorJointsExistAndAreUnique) {
  const Infant infant = make_mimo_v2();
  std::set<std::string> names, joints;
  for (const Actuator& a : infant.actuators) {
    EXPECT_NE(find_joint(infant, a.joint), nullptr) << a.joint;
    EXPECT_TRUE(names.insert(a.name).second) << a.name;
    EXPECT_TRUE(joints.insert(a.joint).second) << a.joint;
  }
  // Every joint except the three slaved upper-trunk joints is actuated.
  EXPECT_EQ(joints.size(), 88u);
  for (const char* slave : {"hip_lean2", "hip_rot2", "hip_bend2"})
    EXPECT_FALSE(joints.contains(slave));
}

TEST(MimoV2Tables, ActuatorOrderAndValues) {
  const Infant infant = make_mimo_v2();
  const auto& a = infant.actuators;
  EXPECT_EQ(a[26].name, "right_ff_side");
  EXPECT_EQ(a[47].name, "right_thumb_distal");
  EXPECT_EQ(a[47].joint, "right_th_distal");
  EXPECT_EQ(a[48].name, "left_ff_side");
  EXPECT_EQ(a[69].name, "left_thumb_distal");
  EXPECT_EQ(a[43].name, "right_thumb_side");
  EXPECT_EQ(a[43].joint, "right_th_swivel");
  EXPECT_DOUBLE_EQ(a[43].gear, .373);
  EXPECT_DOUBLE_EQ(a[43].force_lo, -.345);
  EXPECT_DOUBLE_EQ(a[43 + 22].user[2], 2.604);
  const std::array<const char*, 10> feet = {
      "right_foot_flexion", "right_foot_inversion", "right_foot_rotation", "right_big_toe",
      "right_toes",         "left_foot_flexion",    "left_foot_inversion", "left_foot_rotation",
      "left_toes",          "left_big_toe"};
  for (int i = 0; i < 10; ++i) EXPECT_EQ(a[78 + i].name, feet[i]);
  EXPECT_DOUBLE_EQ(a[81].gear, .165);
  EXPECT_DOUBLE_EQ(a[81].force_hi, .3);
  EXPECT_DOUBLE_EQ(a[81].user[0], 1.774);
  EXPECT_DOUBLE_EQ(a[82].user[0], 1.805);
  EXPECT_DOUBLE_EQ(a[86].user[0], 1.774);
  EXPECT_DOUBLE_EQ(a[87].user[0], 1.805);
}

TEST(MimoV2Tables, TorqueSensorsHaveSitesInReferenceOrder) {
  const Infant infant = make_mimo_v2();
  std::set<std::string> sites;
  for (const Body& b : infant.bodies) {
    for (const Site& s : b.sites) EXPECT_TRUE(sites.insert(s.name).second) << s.name;
  }
  for (const TorqueSensor& t : infant.torque_sensors) {
    EXPECT_TRUE(sites.contains(t.site)) << t.site;
  }
  const auto& t = infant.torque_sensors;
  EXPECT_EQ(t[5].name, "right_shoulder");
  EXPECT_EQ(t[7].name, "right_wrist");
  EXPECT_EQ(t[8].name, "right_ff_knuckle");
  EXPECT_EQ(t[17].name, "right_lf_meta");
  EXPECT_EQ(t[23].name, "right_th_distal");
  EXPECT_EQ(t[24].name, "left_shoulder");
  EXPECT_EQ(t[42].name, "left_th_distal");
  EXPECT_EQ(t[43].name, "right_hip");
  EXPECT_EQ(t[46].name, "right_toes");
  EXPECT_EQ(t[47].name, "right_big_toe");
  EXPECT_EQ(t[52].name, "left_big_toe");
  // Each finger sensor's site sits on the segment body it measures.
  EXPECT_EQ(find_body(infant, "right_thhub")->sites.front().name, "torque_right_th_hub");
  EXPECT_DOUBLE_EQ(find_body(infant, "left_lfmetacarpal")->sites.front().radius, 0.002);
}

TEST(MimoV2Tables, TreeOrderAndUniqueNames) {
  const Infant infant = make_mimo_v2();
  ASSERT_FALSE(infant.bodies.empty());
  EXPECT_EQ(infant.bodies[0].name, "hip");
  EXPECT_TRUE(infant.bodies[0].parent.empty());
  std::set<std::string> seen;
  for (const Body& b : infant.bodies) {
    if (!b.parent.empty()) {
      EXPECT_TRUE(seen.contains(b.parent)) << b.name << " <- " << b.parent;
    }
    EXPECT_TRUE(seen.insert(b.name).second) << b.name;
  }
  const std::vector<std::string> names = joint_names(infant);
  EXPECT_EQ(std::set<std::string>(names.begin(), names.end()).size(), names.size());
  // Left foot lists toes before big_toe, like the reference.
  const std::vector<std::string> tail(names.end() - 11, names.end());
  EXPECT_EQ(tail[0], "right_big_toe");
  EXPECT_EQ(tail[1], "right_toes");
  EXPECT_EQ(tail[2], "left_hip1");
  EXPECT_EQ(tail[9], "left_toes");
  EXPECT_EQ(tail[10], "left_big_toe");
}

TEST(MimoV2Tables, HandValues) {
  const Infant infant = make_mimo_v2();
  const Joint* swivel = find_joint(infant, "right_th_swivel");
  ASSERT_NE(swivel, nullptr);
  EXPECT_DOUBLE_EQ(swivel->range_lo, -10);
  EXPECT_DOUBLE_EQ(swivel->range_hi, 110);
  EXPECT_DOUBLE_EQ(swivel->springref, 40);
  expect_vec(swivel->axis, {3, -5, -1});
  expect_vec(find_joint(infant, "left_th_swivel")->axis, {-3, -5, 1});
  expect_vec(find_joint(infant, "left_th_adduction")->axis, {-1, 2, 0});
  expect_vec(find_joint(infant, "left_th_pivot")->axis, {-1, 0, 0});
  expect_vec(find_joint(infant, "left_lf_meta")->axis, {-0.571, 0, 0.821});
  expect_vec(find_joint(infant, "right_lf_meta")->axis, {0.571, 0, 0.821});
  expect_vec(find_joint(infant, "left_ff_knuckle")->axis, {-1, 0, 0});
  expect_vec(find_joint(infant, "left_rf_distal")->axis, {-1, 0, 0});
  expect_vec(find_joint(infant, "left_mf_side")->axis, {0, 1, 0});
  expect_vec(find_joint(infant, "left_th_middle")->axis, {0, -1, 0});
  expect_vec(find_joint(infant, "right_hand2")->pos, {-0.007, -0.005, -.02032});
  expect_vec(find_joint(infant, "left_hand2")->pos, {-0.007, 0.005, -.02032});
  expect_vec(find_joint(infant, "left_hand1")->axis, {0, 0, 1});
  EXPECT_DOUBLE_EQ(find_joint(infant, "right_mf_knuckle")->stiffness, 0.0010);
  EXPECT_DOUBLE_EQ(find_joint(infant, "right_ff_middle")->frictionloss, 0);

  expect_vec(find_body(infant, "right_hand")->pos, {0.007, -0.009, 0.11032});
  expect_vec(find_body(infant, "left_hand")->pos, {0.007, 0.009, 0.11032});
  expect_vec(find_body(infant, "left_rfknuckle")->pos, {-0.01177, 0, 0.02945});
  const Body* left_base = find_body(infant, "left_thbase");
  expect_vec(left_base->pos, {0.0123, 0.00423, -0.01602});
  expect_vec(left_base->euler, {0, 80, -30});
  expect_vec(find_body(infant, "right_thbase")->euler, {0, 80, 30});
  EXPECT_EQ(find_body(infant, "right_lfknuckle")->parent, "right_lfmetacarpal");
  EXPECT_EQ(find_body(infant, "left_thdistal")->parent, "left_thhub");
  for (const Geom& g : find_body(infant, "right_hand")->geoms) EXPECT_EQ(g.condim, 6);
}

TEST(MimoV2Tables, CollisionBits) {
  const Infant infant = make_mimo_v2();
  const Geom& right_forearm = find_body(infant, "right_lower_arm")->geoms.front();
  EXPECT_EQ(right_forearm.contype, 8);
  EXPECT_EQ(right_forearm.conaffinity, 7);
  const Geom& left_forearm = find_body(infant, "left_lower_arm")->geoms.front();
  EXPECT_EQ(left_forearm.contype, 2);
  EXPECT_EQ(left_forearm.conaffinity, 25);
  for (const char* body : {"right_lfmetacarpal", "right_thbase"}) {
    for (const Geom& g : find_body(infant, body)->geoms) {
      EXPECT_EQ(g.contype, 16);
      EXPECT_EQ(g.conaffinity, 7);
    }
  }
  for (const char* body : {"left_lfmetacarpal", "left_thbase"}) {
    for (const Geom& g : find_body(infant, body)->geoms) {
      EXPECT_EQ(g.contype, 4);
      EXPECT_EQ(g.conaffinity, 25);
    }
  }
  // A forearm never touches its own hand's metacarpal or thumb base, but does touch the other's.
  auto collide = [](const Geom& a, const Geom& b) {
    return (a.contype & b.conaffinity) || (b.contype & a.conaffinity);
  };
  const Geom& right_base = find_body(infant, "right_thbase")->geoms.front();
  const Geom& left_base = find_body(infant, "left_thbase")->geoms.front();
  EXPECT_FALSE(collide(right_forearm, right_base));
  EXPECT_FALSE(collide(left_forearm, left_base));
  EXPECT_TRUE(collide(right_forearm, left_base));
  EXPECT_TRUE(collide(left_forearm, right_base));
}

TEST(MimoV2Tables, FeetAndLocks) {
  const Infant infant = make_mimo_v2();
  expect_vec(find_body(infant, "right_big_toe")->pos, {.053, .0175, 0});
  expect_vec(find_body(infant, "right_toes")->pos, {.053, -.0075, 0});
  expect_vec(find_body(infant, "left_toes")->pos, {.053, .0075, 0});
  expect_vec(find_body(infant, "left_big_toe")->pos, {.053, -.0175, 0});
  for (const char* name : {"right_big_toe", "right_toes", "left_toes", "left_big_toe"}) {
    const Joint* j = find_joint(infant, name);
    ASSERT_NE(j, nullptr) << name;
    EXPECT_DOUBLE_EQ(j->stiffness, .053);
    EXPECT_DOUBLE_EQ(j->damping, .02);
    EXPECT_DOUBLE_EQ(j->frictionloss, .002);
    EXPECT_DOUBLE_EQ(j->armature, .0001);
  }
  EXPECT_EQ(find_body(infant, "right_foot")->geoms.size(), 3u);
  EXPECT_DOUBLE_EQ(find_body(infant, "right_foot")->geoms[1].size[0], .030);
}

}  // namespace
}  // namespace cradle::model

#include "model/mjcf.h"

#include <cmath>
#include <numbers>

#include "core/xml.h"

namespace cradle::model {
namespace {

std::string vec(const Vec3& v) { return nums({v[0], v[1], v[2]}); }
double radians(double degrees) { return degrees * std::numbers::pi / 180.0; }

Attrs geom_attrs(const Geom& g) {
  Attrs a;
  if (!g.name.empty()) a.emplace_back("name", g.name);
  a.emplace_back("type", std::string(geom_type_name(g.type)));
  a.emplace_back("size", nums(g.size));
  a.emplace_back("pos", vec(g.pos));
  if (g.euler != Vec3{0, 0, 0}) a.emplace_back("euler", vec(g.euler));
  a.emplace_back("mass", num(g.mass));
  if (g.friction) a.emplace_back("friction", vec(*g.friction));
  if (g.contype != 1) a.emplace_back("contype", std::to_string(g.contype));
  if (g.conaffinity != 1) a.emplace_back("conaffinity", std::to_string(g.conaffinity));
  if (g.condim != 0) a.emplace_back("condim", std::to_string(g.condim));
  if (!g.material.empty()) a.emplace_back("material", g.material);
  return a;
}

// Muscle actuation replaces the passive spring and most of the damping with the muscles' own
// passive and velocity-dependent forces (mimo_core.md §3.2).
constexpr double kMuscleDampingDivisor = 20;

Attrs joint_attrs(const Joint& j, bool muscle) {
  const double stiffness = muscle ? 0 : j.stiffness;
  const double damping = muscle ? j.damping / kMuscleDampingDivisor : j.damping;
  return {{"name", kJointPrefix + j.name},
          {"type", "hinge"},
          {"axis", vec(j.axis)},
          {"pos", vec(j.pos)},
          {"range", nums({j.range_lo, j.range_hi})},
          {"springref", num(j.springref)},
          {"stiffness", num(stiffness)},
          {"damping", num(damping)},
          {"frictionloss", num(j.frictionloss)},
          {"armature", num(j.armature)}};
}

// Emits one body and, recursively, its children in table order (which keeps document order).
void emit_body(const Infant& infant, const Body& body, bool muscle, XmlWriter& xml) {
  Attrs attrs{{"name", body.name}, {"pos", vec(body.pos)}};
  if (body.euler != Vec3{0, 0, 0}) attrs.emplace_back("euler", vec(body.euler));
  if (body.parent.empty()) attrs.emplace_back("childclass", "mimo");
  xml.open("body", attrs);
  for (const Joint& j : body.joints) xml.leaf("joint", joint_attrs(j, muscle));
  for (const Geom& g : body.geoms) xml.leaf("geom", geom_attrs(g));
  for (const Site& s : body.sites) {
    xml.leaf("site", {{"name", s.name}, {"pos", vec(s.pos)}, {"size", num(s.radius)}});
  }
  for (const Camera& c : body.cameras) {
    xml.leaf("camera", {{"name", c.name},
                        {"mode", "fixed"},
                        {"pos", vec(c.pos)},
                        {"euler", vec(c.euler)},
                        {"fovy", num(c.fovy)}});
  }
  for (const Body& child : infant.bodies) {
    if (child.parent == body.name) emit_body(infant, child, muscle, xml);
  }
  xml.close();
}

const Joint* find_joint(const Infant& infant, const std::string& name) {
  for (const Body& b : infant.bodies) {
    for (const Joint& j : b.joints) {
      if (j.name == name) return &j;
    }
  }
  return nullptr;
}

}  // namespace

InfantXml emit_infant(const Infant& infant, const EmitOptions& options) {
  InfantXml out;

  // Class defaults: only solver parameters, friction and condim matter, as every joint and geom
  // sets its own stiffness, damping, armature and mass.
  XmlWriter defaults;
  defaults.open("default", {{"class", "mimo"}})
      .leaf("joint", {{"limited", "true"},
                      {"damping", ".1"},
                      {"stiffness", ".1"},
                      {"armature", ".001"},
                      {"solimplimit", "0.98 0.99 0.001 .5 1"},
                      {"solreflimit", "0.02 1"}})
      .leaf("geom", {{"condim", "3"},
                     {"material", "skin"},
                     {"friction", "1 0.005 0.0002"},
                     {"solimp", "0.95 0.99 0.001 0.5 1"},
                     {"solref", "0.005 1"}})
      .leaf("site", {{"type", "sphere"}, {"group", "4"}, {"size", "0.01"}})
      .leaf("motor", {{"ctrlrange", "-1 1"}, {"ctrllimited", "true"}, {"forcelimited", "true"}})
      .close();
  out.defaults = defaults.str();

  // Kinematic tree from the root body.
  XmlWriter body(2);
  const bool muscle = options.actuation == ActuationModel::kMuscle;
  emit_body(infant, infant.bodies.front(), muscle, body);
  out.body = body.str();

  XmlWriter contact;
  for (const ContactPair& p : infant.pairs) {
    contact.leaf("pair",
                 {{"geom1", p.geom1}, {"geom2", p.geom2}, {"condim", std::to_string(p.condim)}});
  }
  for (const ContactExclude& e : infant.excludes) {
    contact.leaf("exclude", {{"body1", e.body1}, {"body2", e.body2}});
  }
  out.contact = contact.str();

  XmlWriter tendon;
  for (const FixedTendon& t : infant.tendons) {
    tendon.open("fixed",
                {{"name", t.name}, {"limited", "true"}, {"range", nums({t.range_lo, t.range_hi})}});
    for (const auto& [joint, coef] : t.joints) {
      tendon.leaf("joint", {{"joint", kJointPrefix + joint}, {"coef", num(coef)}});
    }
    tendon.close();
  }
  out.tendon = tendon.str();

  XmlWriter sensor;
  sensor.leaf("accelerometer", {{"name", "vestibular_acc"}, {"site", "vestibular"}});
  sensor.leaf("gyro", {{"name", "vestibular_gyro"}, {"site", "vestibular"}});
  for (const TorqueSensor& t : infant.torque_sensors) {
    if (options.torque_sensors && !options.torque_sensors->contains(t.name)) continue;
    sensor.leaf("torque", {{"name", kTorquePrefix + t.name}, {"site", t.site}});
  }
  out.sensor = sensor.str();

  // Actuators of the enabled groups: motors (spring-damper and muscle models read gear, force
  // range and the muscle user values) or position servos with targets in radians.
  XmlWriter actuator;
  for (const Actuator& a : infant.actuators) {
    if (!options.act_groups[a.group]) continue;
    if (options.actuators && !options.actuators->contains(a.name)) continue;
    const std::string name = kActuatorPrefix + a.name;
    const std::string joint = kJointPrefix + a.joint;
    if (options.actuation == ActuationModel::kPositional) {
      const Joint* j = find_joint(infant, a.joint);
      actuator.leaf("position", {{"name", name},
                                 {"class", "mimo"},
                                 {"joint", joint},
                                 {"kp", num(kPositionalGainPerGear * a.gear)},
                                 {"ctrllimited", "true"},
                                 {"ctrlrange", nums({radians(j->range_lo), radians(j->range_hi)})},
                                 {"forcelimited", "true"},
                                 {"forcerange", nums({a.gear * a.force_lo, a.gear * a.force_hi})}});
    } else {
      Attrs attrs{{"name", name},
                  {"class", "mimo"},
                  {"joint", joint},
                  {"gear", num(a.gear)},
                  {"forcerange", nums({a.force_lo, a.force_hi})},
                  {"user", nums({a.user[0], a.user[1], a.user[2]})}};
      // The muscle model computes the joint torque itself and sends ctrl = torque / gear.
      if (muscle) {
        attrs.emplace_back("ctrllimited", "false");
        attrs.emplace_back("forcelimited", "false");
      }
      actuator.leaf("motor", attrs);
    }
  }
  out.actuator = actuator.str();

  // One lock per joint (holds it at 0 rad); active from the start for the locked groups.
  XmlWriter equality;
  for (const Body& b : infant.bodies) {
    const bool locked = options.lock_groups[body_group(b.name)];
    for (const Joint& j : b.joints) {
      const auto angle = options.lock_angles.find(j.name);
      const bool pinned = angle != options.lock_angles.end();
      const bool active = pinned || (locked && !options.scene_constrained_joints.contains(j.name));
      Attrs attrs{{"name", kJointPrefix + j.name},
                  {"joint1", kJointPrefix + j.name},
                  {"polycoef", pinned ? num(angle->second) + " 1 0 0 0" : "0 1 0 0 0"},
                  {"active", active ? "true" : "false"}};
      attrs.emplace_back("solimp", nums(kLockSolimp));
      attrs.emplace_back("solref", nums(kLockSolref));
      equality.leaf("joint", attrs);
    }
  }
  out.equality = equality.str();
  return out;
}

}  // namespace cradle::model

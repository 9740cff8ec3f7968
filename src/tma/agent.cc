#include "tma/agent.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/error.h"

namespace cradle::tma {

std::string_view kind_name(BodyKind kind) {
  switch (kind) {
    case BodyKind::kWalker:
      return "walker";
    case BodyKind::kSwimmer:
      return "swimmer";
    case BodyKind::kClimber:
      return "climber";
    case BodyKind::kAmphibian:
      return "amphibian";
  }
  return "?";
}

int Agent::state_size() const {
  int n = 2 * static_cast<int>(sensors.size());
  for (const Motor& m : motors) n += m.contact ? 3 : 2;
  return n;
}

void Agent::activate_motors(std::span<const double> action) const {
  for (size_t i = 0; i < motors.size(); ++i) {
    const double a = action[i];
    const double sign = a > 0 ? 1.0 : (a < 0 ? -1.0 : 0.0);
    motors[i].joint->SetMotorSpeed(static_cast<float>(motors[i].speed * sign));
    motors[i].joint->SetMaxMotorTorque(
        static_cast<float>(torque * std::clamp(std::abs(a), 0.0, 1.0)));
  }
}

int Agent::write_state(double* out) const {
  int n = 0;
  for (const Motor& m : motors) {
    out[n++] = m.joint->GetJointAngle() + m.correction;
    out[n++] = m.joint->GetJointSpeed() / m.speed;
    if (m.contact) out[n++] = m.contact->has_contact ? 1.0 : 0.0;
  }
  for (const Sensor& s : sensors) {
    out[n++] = s.tag->has_contact ? 1.0 : 0.0;
    out[n++] = s.tag->has_joint ? 1.0 : 0.0;
  }
  return n;
}

double Agent::mass() const {
  double m = 0;
  for (const b2Body* b : parts) m += b->GetMass();
  for (const Sensor& s : sensors) m += s.body->GetMass();
  return m;
}

// The table of embodiments: sizes the environments need before building one, and the builder
// (the bodies that are never critical, and the climbers, adapted to the one signature).
const std::vector<Embodiment>& embodiments() {
  static const std::vector<Embodiment> table = {
      {"old_classic_bipedal", BodyKind::kWalker, 64 / kScale, 2.5, true, 34 / kScale, 0,
       build_old_classic_bipedal},
      {"small_bipedal", BodyKind::kWalker, 20 / kScale, 37 / kScale, false, 17 / kScale, 0,
       build_small_bipedal},
      {"old_big_quadru", BodyKind::kWalker, 96 / kScale, (102 - 8) / kScale, true, 51 / kScale, 0,
       build_old_big_quadru},
      {"spider", BodyKind::kWalker, 100 / kScale, 24 / kScale, false, 20 / kScale, 0, build_spider},
      {"millipede", BodyKind::kWalker, 80 / kScale, 23 / kScale, false, 10 / kScale, 0,
       [](Agent& a, b2World& w, double x, double y, bool) { build_millipede(a, w, x, y); }},
      {"profile_chimpanzee", BodyKind::kWalker, 24 / kScale, 68 / kScale, false, 28 / kScale, 0,
       [](Agent& a, b2World& w, double x, double y, bool) {
         build_profile_chimpanzee(a, w, x, y);
       }},
      {"climbing_profile_chimpanzee", BodyKind::kClimber, 24 / kScale, 68 / kScale, false,
       28 / kScale, 0,
       [](Agent& a, b2World& w, double x, double y, bool) {
         build_climbing_chimpanzee(a, w, x, y, /*legs=*/true);
       }},
      {"climbing_chest_profile_chimpanzee", BodyKind::kClimber, 24 / kScale, 68 / kScale, false,
       28 / kScale, 0,
       [](Agent& a, b2World& w, double x, double y, bool) {
         build_climbing_chimpanzee(a, w, x, y, /*legs=*/false);
       }},
      {"fish", BodyKind::kSwimmer, 35 / kScale, 9 / kScale, false, 0, 1.0,
       [](Agent& a, b2World& w, double x, double y, bool) { build_fish(a, w, x, y); }},
      {"amphibious_bipedal", BodyKind::kAmphibian, 64 / kScale, 71 / kScale, false, 34 / kScale, 0,
       [](Agent& a, b2World& w, double x, double y, bool) {
         build_amphibious_bipedal(a, w, x, y);
       }},
      {"classic_bipedal", BodyKind::kWalker, 64 / kScale, 71 / kScale, false, 34 / kScale, 0,
       build_classic_bipedal},
      {"big_quadru", BodyKind::kWalker, 96 / kScale, 105 / kScale, false, 51 / kScale, 0,
       build_big_quadru},
      {"wheel", BodyKind::kWalker, 20 / kScale, 30 / kScale, false, 10 / kScale, 0, build_wheel},
  };
  return table;
}

const std::vector<std::string>& embodiment_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const Embodiment& e : embodiments()) out.push_back(e.name);
    return out;
  }();
  return names;
}

const Embodiment& embodiment(std::string_view name) {
  for (const Embodiment& e : embodiments()) {
    if (e.name == name) return e;
  }
  std::string known;
  for (const Embodiment& e : embodiments()) known += (known.empty() ? "" : ", ") + e.name;
  throw UserError("unknown embodiment '" + std::string(name) + "' (expected one of: " + known +
                  ")");
}

void build_agent(std::string_view name, b2World& world, double x0, double y0, double force,
                 bool stump_tracks, Agent& agent, const BodyOptions& options) {
  const Embodiment& e = embodiment(name);
  agent = Agent{};
  agent.kind = e.kind;
  agent.options = options;
  const double y = y0 + e.spawn_dy;
  e.build(agent, world, x0, y, stump_tracks);
  // The initial push acts during the first world step only (Box2D clears forces after a step).
  for (b2Body* b : agent.pushed) b->ApplyForceToCenter(b2Vec2(static_cast<float>(force), 0), true);
}

void destroy_agent(b2World& world, Agent& agent) {
  for (b2Body* b : agent.parts) world.DestroyBody(b);
  for (Sensor& s : agent.sensors) world.DestroyBody(s.body);
  agent = Agent{};
}

namespace build {

b2PolygonShape pixel_polygon(std::initializer_list<b2Vec2> pixels) {
  b2Vec2 v[b2_maxPolygonVertices];
  int n = 0;
  for (const b2Vec2& p : pixels) {
    v[n++] = b2Vec2(static_cast<float>(p.x / kScale), static_cast<float>(p.y / kScale));
  }
  b2PolygonShape shape;
  shape.Set(v, n);
  return shape;
}

b2PolygonShape box(double half_w, double half_h) {
  b2PolygonShape shape;
  shape.SetAsBox(static_cast<float>(half_w), static_cast<float>(half_h));
  return shape;
}

b2Body* part(Agent& agent, b2World& world, b2Vec2 pos, double angle, const b2Shape& shape,
             const Fixture& fixture, bool check_contact, bool critical, Rgb c1, Rgb c2) {
  Tag& tag = agent.tags.emplace_back();
  tag.type = ObjectType::kBody;
  tag.check_contact = check_contact;
  tag.critical = critical;
  tag.color1 = c1;
  tag.color2 = c2;
  b2BodyDef def;
  def.type = b2_dynamicBody;
  def.position = pos;
  def.angle = static_cast<float>(angle);
  def.userData.pointer = reinterpret_cast<uintptr_t>(&tag);
  b2Body* body = world.CreateBody(&def);
  b2FixtureDef fd;
  fd.shape = &shape;
  fd.density = static_cast<float>(fixture.density);
  fd.friction = static_cast<float>(fixture.friction);
  fd.restitution = static_cast<float>(fixture.restitution);
  fd.filter.categoryBits = fixture.category;
  fd.filter.maskBits = fixture.mask;
  fd.isSensor = fixture.sensor;
  body->CreateFixture(&fd);
  agent.parts.push_back(body);
  return body;
}

b2RevoluteJoint* joint(b2World& world, b2Body* a, b2Body* b, b2Vec2 anchor, double lower,
                       double upper, bool motor) {
  b2RevoluteJointDef def;
  def.Initialize(a, b, anchor);
  def.enableLimit = true;
  def.lowerAngle = static_cast<float>(lower);
  def.upperAngle = static_cast<float>(upper);
  def.enableMotor = motor;
  return static_cast<b2RevoluteJoint*>(world.CreateJoint(&def));
}

b2RevoluteJoint* joint_local(b2World& world, b2Body* a, b2Body* b, b2Vec2 local_a, b2Vec2 local_b,
                             double lower, double upper) {
  b2RevoluteJointDef def;
  def.bodyA = a;
  def.bodyB = b;
  def.localAnchorA = local_a;
  def.localAnchorB = local_b;
  def.referenceAngle = b->GetAngle() - a->GetAngle();
  def.enableLimit = true;
  def.lowerAngle = static_cast<float>(lower);
  def.upperAngle = static_cast<float>(upper);
  def.enableMotor = true;
  return static_cast<b2RevoluteJoint*>(world.CreateJoint(&def));
}

void motor(Agent& agent, b2RevoluteJoint* joint, double speed, const b2Body* contact,
           double correction) {
  agent.motors.push_back(Motor{.joint = joint,
                               .speed = speed,
                               .correction = correction,
                               .contact = contact ? tag_of(contact) : nullptr});
}

Chimpanzee chimpanzee(Agent& agent, b2World& world, double x0, double y0, bool legs,
                      bool critical_feet) {
  constexpr double kPi = std::numbers::pi;
  const Rgb hull1{0.5f, 0.4f, 0.9f}, hull2{0.3f, 0.3f, 0.5f};
  const Rgb leg1{0.5f, 0.2f, 0.4f}, leg2{0.3f, 0.1f, 0.2f};
  agent.torque = 100;
  agent.torque_penalty = 3.5e-4 / 5;
  agent.remove_head_angle = true;
  Chimpanzee c;
  // Head and torso collide with terrain only, like the limbs.
  const Fixture body_fd{.density = 5.0, .friction = 0.1, .mask = 0x1};
  const b2PolygonShape head_shape = pixel_polygon({{-5, 10}, {5, 10}, {5, -10}, {-5, -10}});
  b2Body* head = part(agent, world, at(x0, y0 + 45 / kScale / 2 + 20 / kScale / 2 + 0.2), 0,
                      head_shape, body_fd, true, true, hull1, hull2);
  agent.head = head;
  agent.pushed.push_back(head);
  const b2PolygonShape torso_shape = pixel_polygon({{-12, 25}, {12, 25}, {8, -20}, {-8, -20}});
  c.torso = part(agent, world, at(x0, y0), 0, torso_shape, body_fd, true, true, hull1, hull2);
  joint(world, head, c.torso, at(x0, y0 + 45 / kScale / 2), -0.1 * kPi, 0.1 * kPi, false);
  const double down = Chimpanzee::kLegDown, h = Chimpanzee::kLimbH;
  for (int k = 0; legs && k < 2; ++k) {
    b2Body* upper = part(agent, world, at(x0, y0 - h / 2 - down), 0, c.upper, c.limb_fd, false,
                         false, leg1, leg2);
    motor(agent, joint(world, c.torso, upper, at(x0, y0 - down), -0.3 * kPi, 0.6 * kPi, true), 4);
    b2Body* lower = part(agent, world, at(x0, y0 - h * 1.5 - down), 0, c.lower, c.limb_fd, true,
                         critical_feet, leg1, leg2);
    motor(agent, joint(world, upper, lower, at(x0, y0 - h - down), -0.75 * kPi, -0.1, true), 6,
          lower, 1.0);
  }
  return c;
}

}  // namespace build
}  // namespace cradle::tma

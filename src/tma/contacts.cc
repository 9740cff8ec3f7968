#include "tma/contacts.h"

#include <algorithm>

namespace cradle::tma {
namespace {

bool is(const b2Body* body, ObjectType type) { return tag_of(body)->type == type; }

void remove_one(std::vector<b2Body*>& list, b2Body* body) {
  auto it = std::find(list.begin(), list.end(), body);
  if (it != list.end()) list.erase(it);
}

}  // namespace

void ContactListener::BeginContact(b2Contact* contact) {
  b2Fixture* fa = contact->GetFixtureA();
  b2Fixture* fb = contact->GetFixtureB();
  b2Body* bodies[2] = {fa->GetBody(), fb->GetBody()};
  if (parkour_) {
    // Water first, then hand sensors, then any other sensor (creepers) is ignored.
    if (is(bodies[0], ObjectType::kWater) || is(bodies[1], ObjectType::kWater)) {
      begin_water(fa, fb);
      return;
    }
    if (is(bodies[0], ObjectType::kBodySensor) || is(bodies[1], ObjectType::kBodySensor)) {
      begin_sensor(bodies[0], bodies[1]);
      return;
    }
    if (fa->IsSensor() || fb->IsSensor()) return;
  }
  for (int k = 0; k < 2; ++k) {
    Tag* tag = tag_of(bodies[k]);
    if (tag->type != ObjectType::kBody || !tag->check_contact) continue;
    tag->has_contact = true;
    if (!tag->critical) continue;
    // Climbers may touch the ceiling with their critical parts.
    const bool grip = parkour_ && agent_ && agent_->kind == BodyKind::kClimber &&
                      is(bodies[1 - k], ObjectType::kGripTerrain);
    if (!grip) critical = true;
  }
}

void ContactListener::EndContact(b2Contact* contact) {
  b2Fixture* fa = contact->GetFixtureA();
  b2Fixture* fb = contact->GetFixtureB();
  b2Body* bodies[2] = {fa->GetBody(), fb->GetBody()};
  if (parkour_) {
    if (is(bodies[0], ObjectType::kWater) || is(bodies[1], ObjectType::kWater)) {
      end_water(fa, fb);
      return;
    }
    if (is(bodies[0], ObjectType::kBodySensor) || is(bodies[1], ObjectType::kBodySensor)) {
      end_sensor(bodies[0], bodies[1]);
      return;
    }
  }
  // No sensor test here (reference quirk): leaving a creeper clears a foot's flag.
  for (b2Body* body : bodies) {
    Tag* tag = tag_of(body);
    if (tag->type == ObjectType::kBody && tag->check_contact) tag->has_contact = false;
  }
}

void ContactListener::begin_water(b2Fixture* a, b2Fixture* b) {
  if (is(a->GetBody(), ObjectType::kWater) && is(b->GetBody(), ObjectType::kBody)) {
    water_pairs.emplace_back(a, b);
  } else if (is(b->GetBody(), ObjectType::kWater) && is(a->GetBody(), ObjectType::kBody)) {
    water_pairs.emplace_back(b, a);
  }
}

void ContactListener::end_water(b2Fixture* a, b2Fixture* b) {
  for (auto pair : {std::pair(a, b), std::pair(b, a)}) {
    auto it = std::find(water_pairs.begin(), water_pairs.end(), pair);
    if (it != water_pairs.end()) water_pairs.erase(it);
  }
}

void ContactListener::begin_sensor(b2Body* a, b2Body* b) {
  b2Body* bodies[2] = {a, b};
  for (int k = 0; k < 2; ++k) {
    Tag* tag = tag_of(bodies[k]);
    if (tag->type != ObjectType::kBodySensor || !tag->check_contact || !agent_) continue;
    b2Body* other = bodies[1 - k];
    if (!is(other, ObjectType::kGripTerrain) && !is(other, ObjectType::kCreeper)) return;
    agent_->sensors[tag->sensor].touching.push_back(other);
    tag->has_contact = true;
  }
}

void ContactListener::end_sensor(b2Body* a, b2Body* b) {
  b2Body* bodies[2] = {a, b};
  for (int k = 0; k < 2; ++k) {
    Tag* tag = tag_of(bodies[k]);
    if (tag->type != ObjectType::kBodySensor || !tag->check_contact || !agent_) continue;
    if (!tag->has_contact) continue;
    std::vector<b2Body*>& list = agent_->sensors[tag->sensor].touching;
    remove_one(list, bodies[1 - k]);
    if (list.empty()) tag->has_contact = false;
  }
}

void climbing_before_step(b2World& world, Agent& agent, const double* grasp_actions) {
  for (size_t i = 0; i < agent.sensors.size(); ++i) {
    Sensor& s = agent.sensors[i];
    if (grasp_actions[i] > 0) {
      s.tag->ready = true;
      continue;
    }
    s.tag->ready = false;
    if (s.tag->has_joint) {
      s.tag->has_joint = false;
      if (s.grasp) world.DestroyJoint(s.grasp);
      s.grasp = nullptr;
    }
  }
}

void climbing_after_step(b2World& world, Agent& agent) {
  constexpr float kReach = 0.05f + 0.01f;
  for (Sensor& s : agent.sensors) {
    if (s.touching.empty() || !s.tag->ready || s.tag->has_joint) continue;
    b2Body* other = s.touching.front();
    // Coarse test against the bounding box of the other body's first-fixture vertices, read in its
    // local frame (the world frame for static terrain, as in the reference).
    const b2Shape* shape = other->GetFixtureList()->GetShape();
    b2Vec2 lo(1e30f, 1e30f), hi(-1e30f, -1e30f);
    auto grow = [&](const b2Vec2& v) {
      lo = b2Min(lo, v);
      hi = b2Max(hi, v);
    };
    if (shape->GetType() == b2Shape::e_edge) {
      const auto* edge = static_cast<const b2EdgeShape*>(shape);
      grow(edge->m_vertex1);
      grow(edge->m_vertex2);
    } else if (shape->GetType() == b2Shape::e_polygon) {
      const auto* poly = static_cast<const b2PolygonShape*>(shape);
      for (int k = 0; k < poly->m_count; ++k) grow(poly->m_vertices[k]);
    }
    const b2Vec2 c = s.body->GetWorldCenter();
    const bool overlaps =
        c.x + kReach > lo.x && c.x - kReach < hi.x && c.y + kReach > lo.y && c.y - kReach < hi.y;
    if (overlaps) {
      b2RevoluteJointDef def;
      def.Initialize(s.body, other, c);
      s.grasp = world.CreateJoint(&def);
      s.tag->has_joint = true;
    } else {
      s.touching.erase(s.touching.begin());
      if (s.touching.empty()) s.tag->has_contact = false;
    }
  }
}

}  // namespace cradle::tma

// The contact listener of both environments (tma_bodies.md §3.2-3.4): contact flags and fatal
// contacts of the agent's parts, the (water, part) fixture pairs that water.cc pushes, and the
// graspable bodies each climber hand sensor touches.
#pragma once

#include <box2d/box2d.h>

#include <utility>
#include <vector>

#include "tma/agent.h"

namespace cradle::tma {

class ContactListener : public b2ContactListener {
 public:
  ContactListener() { water_pairs.reserve(64); }
  // Parkour dispatches water and sensor contacts to their handlers; Stump Tracks only flags parts.
  void configure(bool parkour, Agent* agent) {
    parkour_ = parkour;
    agent_ = agent;
  }
  void clear() {
    water_pairs.clear();
    critical = false;
  }
  void BeginContact(b2Contact* contact) override;
  void EndContact(b2Contact* contact) override;

  bool critical = false;                                       // a fatal contact happened (latched)
  std::vector<std::pair<b2Fixture*, b2Fixture*>> water_pairs;  // (water, body part)

 private:
  void begin_water(b2Fixture* a, b2Fixture* b);
  void end_water(b2Fixture* a, b2Fixture* b);
  void begin_sensor(b2Body* a, b2Body* b);
  void end_sensor(b2Body* a, b2Body* b);
  bool parkour_ = false;
  Agent* agent_ = nullptr;
};

// Climbing (tma_bodies.md §3.4). Before the world step: the grasp actions (the last
// agent.sensors.size() components) make sensors ready, or release their grip.
void climbing_before_step(b2World& world, Agent& agent, const double* grasp_actions);
// After the world step: ready, free sensors that touch a graspable body get a revolute joint.
void climbing_after_step(b2World& world, Agent& agent);

}  // namespace cradle::tma

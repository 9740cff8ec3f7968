// An embodiment in a Box2D world: its parts, motors and (climbers) hand sensors, the observation of
// its motors and the motor commands. One builder per embodiment lives in walkers.cc, climbers.cc
// and swimmers.cc; `embodiment()` describes them and `build_agent()` creates one.
#pragma once

#include <box2d/box2d.h>

#include <deque>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "tma/physics.h"

namespace cradle::tma {

enum class BodyKind { kWalker, kSwimmer, kClimber, kAmphibian };
std::string_view kind_name(BodyKind kind);

struct Motor {
  b2RevoluteJoint* joint = nullptr;
  double speed = 1;              // rad/s at full command; also the observation's speed divisor
  double correction = 0;         // added to the observed angle
  const Tag* contact = nullptr;  // body whose contact flag is observed, if any
};

struct Sensor {
  b2Body* body = nullptr;
  Tag* tag = nullptr;
  std::vector<b2Body*> touching;  // graspable bodies in contact, in order of first contact
  b2Joint* grasp = nullptr;       // the revolute joint holding the grip, if any
};

// Build options of the reference bodies that change their shape (TmaOptions checks which body
// takes which).
struct BodyOptions {
  int nb_of_bodies = 4;      // millipede segments
  int nb_pairs_of_legs = 2;  // spider
};

struct Agent {
  BodyKind kind = BodyKind::kWalker;
  BodyOptions options;             // what the builder reads
  double torque = 80;              // MOTORS_TORQUE
  double torque_penalty = 3.5e-4;  // TORQUE_PENALTY
  bool remove_head_angle = false;  // reward without the head-angle term
  std::vector<b2Body*> parts;      // body parts in creation order (sensors excluded)
  std::vector<Motor> motors;
  std::vector<Sensor> sensors;
  b2Body* head = nullptr;       // reference object: reward, lidar origin, observation
  std::vector<b2Body*> pushed;  // bodies that get the initial random force
  std::deque<Tag> tags;         // stable storage behind the bodies' user data

  int action_size() const { return static_cast<int>(motors.size() + sensors.size()); }
  int state_size() const;  // motor observations plus two per sensor
  // Motor speed = speed * sign(a), max torque = torque * |clip(a, -1, 1)|.
  void activate_motors(std::span<const double> action) const;
  // Writes the motor (and sensor) observations; returns the number written.
  int write_state(double* out) const;
  double mass() const;  // every part and sensor
};

// Builds an embodiment's parts with its origin at (x0, y0); `stump_tracks` makes walker hulls
// critical.
using Builder = void (*)(Agent&, b2World&, double x0, double y0, bool stump_tracks);

// What the environments need to place an embodiment before building it, and its builder.
struct Embodiment {
  std::string name;
  BodyKind kind;
  double width;          // AGENT_WIDTH
  double center_height;  // AGENT_CENTER_HEIGHT
  bool old_morphology;   // spawned at TERRAIN_HEIGHT + 2 * leg_h in Stump Tracks
  double leg_h;
  double spawn_dy;  // added to the spawn height by the body itself (fish: +1)
  Builder build;
};

// Every embodiment's name, in the seed's order first.
const std::vector<std::string>& embodiment_names();
// Throws cradle::UserError naming the known embodiments for an unknown name.
const Embodiment& embodiment(std::string_view name);

// Builds `name` with its origin at (x0, y0) (before spawn_dy), pushing its head with `force`.
// `stump_tracks` makes walker hulls critical (reset_on_hull_critical_contact).
void build_agent(std::string_view name, b2World& world, double x0, double y0, double force,
                 bool stump_tracks, Agent& agent, const BodyOptions& options = {});
void destroy_agent(b2World& world, Agent& agent);

// Builders shared by the family files.
namespace build {

struct Fixture {
  double density = 1.0;
  double friction = 0.2;
  double restitution = 0.0;
  std::uint16_t category = kAgentBits;
  std::uint16_t mask = 0x0F;
  bool sensor = false;
};

// A polygon from reference pixel coordinates (divided by kScale).
b2PolygonShape pixel_polygon(std::initializer_list<b2Vec2> pixels);
b2PolygonShape box(double half_w, double half_h);

// A dynamic part at `pos` (world) with one fixture; the tag says its contact flags.
b2Body* part(Agent& agent, b2World& world, b2Vec2 pos, double angle, const b2Shape& shape,
             const Fixture& fixture, bool check_contact, bool critical, Rgb c1, Rgb c2);

// A revolute joint anchored at a world point (pybox2d's `anchor=`: reference angle = angB - angA).
b2RevoluteJoint* joint(b2World& world, b2Body* a, b2Body* b, b2Vec2 anchor, double lower,
                       double upper, bool motor);
// A revolute joint from explicit local anchors; the reference angle is still angB - angA.
b2RevoluteJoint* joint_local(b2World& world, b2Body* a, b2Body* b, b2Vec2 local_a, b2Vec2 local_b,
                             double lower, double upper);
void motor(Agent& agent, b2RevoluteJoint* joint, double speed, const b2Body* contact = nullptr,
           double correction = 0);
// What the chimpanzees share: limb sizes (world units), the torso their limbs hang from, the limb
// fixture (terrain only) and the limb shapes.
struct Chimpanzee {
  static constexpr double kLegDown = 12 / kScale, kArmUp = 22 / kScale;
  static constexpr double kLimbW = 8 / kScale, kLimbH = 28 / kScale;
  static constexpr double kHandW = 4 / kScale, kHandH = 8 / kScale;
  b2Body* torso = nullptr;
  Fixture limb_fd{.mask = 0x1};
  b2PolygonShape upper = box(kLimbW / 2, kLimbH / 2), lower = box(0.8 * kLimbW / 2, kLimbH / 2);
  b2PolygonShape hand = box(kHandW / 2, kHandH / 2);
};
// A chimpanzee up to its arms (which differ): torque, the critical head (the reference object) on a
// passive neck over the torso and, with `legs`, two identical legs (they overlap at spawn, as in
// the reference) whose lower parts are critical when `critical_feet`.
Chimpanzee chimpanzee(Agent& agent, b2World& world, double x0, double y0, bool legs,
                      bool critical_feet);

}  // namespace build

// Family builders (walkers.cc, climbers.cc, swimmers.cc).
void build_old_classic_bipedal(Agent&, b2World&, double x0, double y0, bool critical_hull);
void build_classic_bipedal(Agent&, b2World&, double x0, double y0, bool critical_hull);
void build_small_bipedal(Agent&, b2World&, double x0, double y0, bool critical_hull);
void build_amphibious_bipedal(Agent&, b2World&, double x0, double y0);
void build_old_big_quadru(Agent&, b2World&, double x0, double y0, bool critical_hull);
void build_spider(Agent&, b2World&, double x0, double y0, bool critical_hull);
void build_millipede(Agent&, b2World&, double x0, double y0);
void build_big_quadru(Agent&, b2World&, double x0, double y0, bool critical_hull);
void build_wheel(Agent&, b2World&, double x0, double y0, bool critical_hull);
void build_profile_chimpanzee(Agent&, b2World&, double x0, double y0);
void build_climbing_chimpanzee(Agent&, b2World&, double x0, double y0, bool legs);
void build_fish(Agent&, b2World&, double x0, double y0);

}  // namespace cradle::tma

// The worlds MIMo lives in: the base room (always present) and the crib and cubes scenes, as MJCF
// fragments that the composer (compose.h) places around the infant.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "core/config.h"
#include "model/textures.h"

namespace cradle::scene {

using SceneKind = cradle::SceneKind;

struct WorldFragments {
  std::vector<model::TextureAsset> textures;  // generated images, written as PNG beside scene.xml
  std::vector<model::MaterialAsset> materials;
  std::string assets;     // extra <asset> children (builtin textures, skybox, ...)
  std::string worldbody;  // lights, cameras, static and free bodies placed in <worldbody>
  std::string contact;    // <pair>/<exclude> elements
  std::string equality;   // <weld>/<joint> elements (may name MIMo bodies and robot: joints)
  std::string tendon;     // <fixed>/<spatial> elements (may name robot: joints)
};

// Base room: floor planes, rug, skybox, five lights, cameras corner/top/side1/side2/closeup.
WorldFragments base_world();
// Children of <visual> for the base room: map force/fog/shadow clip, no headlight, no shadows.
std::string base_visual();
// What the scene adds to the base room (empty for kBase). mattress_friction_applies: the crib
// mattress's friction 0.1 overrides MIMo's (Cradle's opt-in; the reference mixes by maximum).
WorldFragments scene_world(SceneKind kind, bool mattress_friction_applies = false);

// Pose of the body "mimo_location" (which carries MIMo's free joint) in each scene.
struct Placement {
  std::array<double, 3> pos{0, 0, 0};
  std::array<double, 4> quat{1, 0, 0, 0};  // w x y z
};
Placement mimo_placement(SceneKind kind);

}  // namespace cradle::scene

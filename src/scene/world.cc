#include "scene/world.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string_view>

#include "core/xml.h"

namespace cradle::scene {
namespace {

std::string vec(double x, double y, double z) { return nums({x, y, z}); }

// Teal rug pattern: a woven teal ground, a lighter diamond lattice and cream dots at the diamond
// centres. Four lattice periods per image side, so the image tiles seamlessly.
model::Image rug_image() {
  constexpr int kSide = 256;
  constexpr double kPeriods = 4.0;
  model::Image image{kSide, kSide, std::vector<std::uint8_t>(kSide * kSide * 3)};
  for (int row = 0; row < kSide; ++row) {
    for (int col = 0; col < kSide; ++col) {
      const double u = kPeriods * col / kSide;
      const double v = kPeriods * row / kSide;
      // Manhattan distance to the nearest cell centre, 0 (centre) to 1 (corner).
      const double d = std::abs(u - std::floor(u) - 0.5) + std::abs(v - std::floor(v) - 0.5);
      const int weave = ((row + col) % 4 < 2) ? 8 : 0;
      std::uint8_t rgb[3] = {static_cast<std::uint8_t>(24 + weave),
                             static_cast<std::uint8_t>(112 + weave),
                             static_cast<std::uint8_t>(116 + weave)};
      if (std::abs(d - 0.5) < 0.04) {
        rgb[0] = 118, rgb[1] = 196, rgb[2] = 188;
      } else if (d < 0.1) {
        rgb[0] = 236, rgb[1] = 226, rgb[2] = 200;
      }
      std::uint8_t* pixel = &image.rgb[(row * kSide + col) * 3];
      pixel[0] = rgb[0], pixel[1] = rgb[1], pixel[2] = rgb[2];
    }
  }
  return image;
}

// One crib rail panel in its own frame: a top rail along local y (half-length `half`) and five
// vertical bars hanging 0.5 m below it at y = 0, ±0.2, ±0.4.
std::string rail_geoms(double half) {
  std::string xml = "<geom type=\"box\" size=\"0.01 0.02 " + num(half) +
                    "\" euler=\"90 0 0\" material=\"matcrib\"/>\n";
  for (double y : {-0.4, -0.2, 0.0, 0.2, 0.4}) {
    xml += "<geom type=\"cylinder\" size=\"0.01 0.25\" pos=\"" + vec(0, y, -0.25) +
           "\" material=\"matcrib\"/>\n";
  }
  return xml;
}

// A static crib sub-body holding one rail panel.
std::string rail_body(std::string_view name, double x, double y, double yaw, double half) {
  return "<body name=\"" + std::string(name) + "\" pos=\"" + vec(x, y, 0.62) + "\" euler=\"" +
         vec(0, 0, yaw) + "\">\n" + rail_geoms(half) + "</body>\n";
}

WorldFragments crib_world(bool mattress_friction_applies) {
  WorldFragments crib;
  // Light-wood checker with dark edge marks; plain off-white mattress.
  crib.assets =
      "<texture name=\"texcrib\" type=\"2d\" builtin=\"checker\" rgb1=\".87 .72 .53\" "
      "rgb2=\".87 .72 .53\" mark=\"edge\" markrgb=\".25 .17 .7\" width=\"100\" height=\"100\"/>\n";
  crib.materials = {{"matcrib", "texcrib", "texrepeat=\"100 100\""},
                    {"matmattress", "", "rgba=\".98 .94 .9 1\""}};

  std::string body = "<body name=\"crib\" pos=\"0 0 0\">\n";
  // End rails (feet at +x, head at -x) and side rails (rotated to run along x).
  body += rail_body("crib_feet", 0.5, 0, 0, 0.425);
  body += rail_body("crib_head", -0.6, 0, 0, 0.425);
  body += rail_body("crib_left", -0.05, 0.425, 90, 0.56);
  body += rail_body("crib_right", -0.05, -0.425, 90, 0.56);
  // Base: frame, floor board, legs and mattress.
  body += "<body name=\"crib_base\" pos=\"0 0 0.15\">\n";
  for (double x : {0.5, -0.6}) {
    body += "<geom type=\"box\" size=\"0.01 0.04 0.425\" pos=\"" + vec(x, 0, 0) +
            "\" euler=\"90 0 0\" material=\"matcrib\"/>\n";
  }
  for (double y : {0.425, -0.425}) {
    body += "<geom type=\"box\" size=\"0.01 0.04 0.56\" pos=\"" + vec(-0.05, y, 0) +
            "\" euler=\"90 90 0\" material=\"matcrib\"/>\n";
  }
  body += "<geom type=\"box\" size=\"0.55 0.425 0.01\" pos=\"-0.05 0 0\" material=\"matcrib\"/>\n";
  for (double x : {0.475, -0.575}) {
    for (double y : {0.4, -0.4}) {
      body += "<geom type=\"cylinder\" size=\"0.02 0.075\" pos=\"" + vec(x, y, -0.075) +
              "\" material=\"matcrib\"/>\n";
    }
  }
  // Mattress with the reference's friction 0.1. As in the reference it has no contact priority
  // and MuJoCo's default solver parameters: against MIMo, MuJoCo takes the element-wise maximum
  // friction (MIMo's 1-5) and averages solref/solimp. Opt-in (mattress_friction_applies):
  // priority="1" makes the mattress's friction apply to MIMo, with solref/solimp set to the
  // average the reference's mix gives against MIMo's skin (solref .005 1, solimp .95 .99 .001 .5
  // 1 with the defaults .02 1, .9 .95 .001 .5 2), so only the friction differs.
  body +=
      "<geom name=\"mattress\" type=\"box\" size=\"0.52 0.4 0.075\" pos=\"-0.05 0 0.025\" "
      "material=\"matmattress\" friction=\"0.1 0.0005 0.00001\"";
  body += mattress_friction_applies
              ? " priority=\"1\" solref=\"0.0125 1\" solimp=\"0.925 0.97 0.001 0.5 1.5\"/>\n"
              : "/>\n";
  body += "</body>\n</body>\n";
  crib.worldbody = body;
  // MIMo's lower trunk is welded to the world at its reference pose.
  crib.equality = "<weld body1=\"lower_body\"/>\n";
  return crib;
}

// One free toy: a box (half-sizes) or a sphere (radius), yawed about z by `yaw` degrees.
struct Toy {
  std::string_view name;
  bool box;
  double size[3];
  double pos[3];
  double yaw;
  std::string_view material;
};

// The sixteen toys of the cubes scene (§2.7).
constexpr Toy kToys[] = {
    {"red_cube", true, {.03, .03, .03}, {.05, .30, .03}, 0, "brick_red"},
    {"yellow_cube", true, {.03, .03, .03}, {.06, .30, .10}, 10, "flax"},
    {"blue_cube", true, {.02, .02, .02}, {.06, .30, .16}, 15, "cambridge_blue"},
    {"green_sphere", false, {.025}, {.10, -.20, .03}, 0, "cambridge_blue"},
    {"blue_sphere", false, {.02}, {.15, -.30, .02}, 0, "antique_fucsia"},
    {"orange_sphere", false, {.04}, {.10, .20, .04}, 0, "apricot"},
    {"red_sphere", false, {.10}, {-.15, .35, .11}, 0, "brick_red"},
    {"yellow_sphere", false, {.05}, {-.16, -.14, .05}, 0, "flax"},
    {"castle_base1", true, {.03, .03, .05}, {-.20, -.40, .05}, 40, "antique_fucsia"},
    {"castle_base2", true, {.03, .03, .05}, {-.10, -.50, .05}, 70, "coral"},
    {"castle_bridge", true, {.045, .125, .025}, {-.15, -.45, .12}, 45, "corn_blue"},
    {"castle_top1", true, {.03, .03, .03}, {-.10, -.50, .18}, 50, "cambridge_blue"},
    {"castle_tower1", true, {.03, .03, .05}, {-.175, -.425, .20}, 50, "flax"},
    {"castle_top2", true, {.03, .03, .03}, {.35, -.03, .03}, 55, "apricot"},
    {"castle_top3", true, {.03, .03, .03}, {-.05, -.205, .03}, 45, "acqua"},
    {"castle_top4", true, {.03, .03, .03}, {-.175, -.425, .28}, 30, "coral"},
};

// Toy colours (pastel_purple is defined but unused, as in the reference).
struct Paint {
  std::string_view name;
  double rgb[3];
};
constexpr Paint kPaints[] = {
    {"brick_red", {.79, .25, .32}},      {"flax", {.93, .86, .51}},
    {"cambridge_blue", {.64, .76, .68}}, {"antique_fucsia", {.57, .36, .51}},
    {"apricot", {.98, .80, .69}},        {"coral", {.94, .50, .50}},
    {"corn_blue", {.58, .80, .92}},      {"acqua", {.73, .83, .90}},
    {"pastel_purple", {.69, .61, .85}},
};

// Joint angles (radians) that hold MIMo sitting in the cubes scene.
struct JointLock {
  std::string_view joint;
  double angle;
};
constexpr JointLock kSittingLocks[] = {
    {"hip_bend1", 0.532},  {"hip_lean1", 0},      {"hip_rot1", 0},       {"hip_bend2", 0.532},
    {"hip_lean2", 0},      {"hip_rot2", 0},       {"head_tilt", 0.4},    {"head_tilt_side", 0},
    {"right_hip1", -1.22}, {"right_hip2", -0.70}, {"right_hip3", 0.538}, {"right_knee", -1.45},
    {"left_hip1", -1.41},  {"left_hip2", -0.823}, {"left_hip3", 0.612},  {"left_knee", -2.14},
};

WorldFragments cubes_world() {
  WorldFragments cubes;
  for (const Paint& paint : kPaints) {
    cubes.materials.push_back({std::string(paint.name), "",
                               "rgba=\"" + vec(paint.rgb[0], paint.rgb[1], paint.rgb[2]) +
                                   " 1\" shininess=\"0.99\" reflectance=\"0\""});
  }
  // Free toys with density 200 kg/m^3 (mass follows from the geom volume).
  for (const Toy& toy : kToys) {
    const std::string size =
        toy.box ? vec(toy.size[0], toy.size[1], toy.size[2]) : num(toy.size[0]);
    cubes.worldbody +=
        "<body name=\"" + std::string(toy.name) + "\" pos=\"" +
        vec(toy.pos[0], toy.pos[1], toy.pos[2]) + "\" euler=\"" + vec(0, 0, toy.yaw) +
        "\">\n<freejoint/>\n<geom type=\"" + (toy.box ? "box" : "sphere") + "\" size=\"" + size +
        "\" density=\"200\" material=\"" + std::string(toy.material) + "\"/>\n</body>\n";
  }
  // MIMo's root is welded in place; polycoef is not angle-converted, so the locks are radians.
  // The locks use the infant's stiff lock parameters: with MuJoCo's defaults they sag by up to
  // 0.013 rad under gravity and the joint springs, and the sitting pose should hold within 1e-3.
  cubes.equality = "<weld body1=\"mimo_location\"/>\n";
  for (const JointLock& lock : kSittingLocks) {
    cubes.equality += "<joint joint1=\"robot:" + std::string(lock.joint) + "\" polycoef=\"" +
                      num(lock.angle) + " 0 0 0 0\" solimp=\"" + nums(model::kLockSolimp) +
                      "\" solref=\"" + nums(model::kLockSolref) + "\"/>\n";
  }
  return cubes;
}

}  // namespace

WorldFragments base_world() {
  WorldFragments base;
  // Rug image (256x256, tiling) replaces the reference's 4962x4962 photo; texuniform keeps the
  // tile size independent of the thin cylinder's half-height.
  base.textures.push_back({"texrug", "2d", {{"file", rug_image()}}, ""});
  // Skybox, floor grid and the unused wall texture are MuJoCo builtins.
  base.assets =
      "<texture type=\"skybox\" builtin=\"gradient\" rgb1=\".8 .8 .8\" rgb2=\".9 .9 .9\" "
      "width=\"100\" height=\"100\"/>\n"
      "<texture name=\"texfloor\" type=\"2d\" builtin=\"checker\" rgb1=\".9 .9 .9\" "
      "rgb2=\".9 .9 .9\" mark=\"edge\" markrgb=\".7 .7 .7\" width=\"100\" height=\"100\"/>\n"
      "<texture name=\"texwall\" type=\"2d\" builtin=\"flat\" rgb1=\".99 .99 .99\" "
      "width=\"100\" height=\"100\"/>\n";
  base.materials = {{"mattransparent", "", "rgba=\"1 1 1 0\""},
                    {"matfloor", "texfloor", "texrepeat=\"25 25\""},
                    {"matrug", "texrug",
                     "shininess=\".1\" specular=\".5\" texrepeat=\"2 2\" "
                     "texuniform=\"true\""}};
  base.worldbody =
      // One soft light from above and four corner lights aimed at the centre.
      "<light directional=\"true\" pos=\"0 0 5\" dir=\"0 0 -1\" ambient=\".2 .2 .2\" "
      "diffuse=\".1 .1 .1\" specular=\"0 0 0\"/>\n"
      "<light directional=\"true\" pos=\"2 2 2\" dir=\"-1 -1 -1\" ambient=\".05 .05 .05\" "
      "diffuse=\".2 .2 .2\" specular=\".3 .3 .3\" castshadow=\"false\"/>\n"
      "<light directional=\"true\" pos=\"-2 2 2\" dir=\"1 -1 -1\" ambient=\".05 .05 .05\" "
      "diffuse=\".2 .2 .2\" specular=\".3 .3 .3\" castshadow=\"false\"/>\n"
      "<light directional=\"true\" pos=\"-2 -2 2\" dir=\"1 1 -1\" ambient=\".05 .05 .05\" "
      "diffuse=\".2 .2 .2\" specular=\".3 .3 .3\" castshadow=\"false\"/>\n"
      "<light directional=\"true\" pos=\"2 -2 2\" dir=\"-1 1 -1\" ambient=\".05 .05 .05\" "
      "diffuse=\".2 .2 .2\" specular=\".3 .3 .3\" castshadow=\"false\"/>\n"
      // Cameras; corner and closeup keep MIMo's root in view.
      "<camera name=\"corner\" mode=\"targetbody\" target=\"mimo_location\" pos=\"3 -3 3\" "
      "fovy=\"20\"/>\n"
      "<camera name=\"top\" pos=\"0 0 2\" euler=\"0 0 90\"/>\n"
      "<camera name=\"side1\" pos=\"2 0 .5\" euler=\"90 90 0\"/>\n"
      "<camera name=\"side2\" pos=\"0 2 .5\" euler=\"90 180 0\"/>\n"
      "<camera name=\"closeup\" mode=\"targetbody\" target=\"mimo_location\" "
      "pos=\"0.25 -0.25 1\"/>\n"
      // Invisible physical floor at z = 0, the visible floor and rug just below it.
      "<geom name=\"transparent\" type=\"plane\" size=\"2 2 .05\" material=\"mattransparent\" "
      "conaffinity=\"1\"/>\n"
      "<geom name=\"floor\" type=\"plane\" pos=\"0 0 -0.01\" size=\"5 5 .05\" "
      "material=\"matfloor\" conaffinity=\"1\"/>\n"
      "<geom name=\"rug\" type=\"cylinder\" pos=\"0 0 -0.005\" size=\"1 0.0045\" "
      "material=\"matrug\" conaffinity=\"1\"/>\n";
  return base;
}

std::string base_visual() {
  return "<map force=\"0.1\" fogend=\"10\" shadowclip=\"3\"/>\n"
         "<quality shadowsize=\"0\"/>\n"
         "<headlight active=\"0\"/>\n";
}

WorldFragments scene_world(SceneKind kind, bool mattress_friction_applies) {
  switch (kind) {
    case SceneKind::kCrib:
      return crib_world(mattress_friction_applies);
    case SceneKind::kCubes:
      return cubes_world();
    case SceneKind::kBase:
      break;
  }
  return {};
}

Placement mimo_placement(SceneKind kind) {
  // euler "0 -90 0": a -90 degree turn about y, quaternion (cos 45°, 0, -sin 45°, 0).
  const double half = std::sqrt(0.5);
  switch (kind) {
    case SceneKind::kBase:
      return {{0, 0, 0.1}, {half, 0, -half, 0}};
    case SceneKind::kCrib:
      return {{0, 0, 0.3}, {half, 0, -half, 0}};
    case SceneKind::kCubes:
      return {{0, 0, 0.0467196}, {0.885453, -0.000184209, -0.464728, -0.000527509}};
  }
  return {};
}

}  // namespace cradle::scene

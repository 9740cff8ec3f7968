#include "scene/world.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>
#include <stb_image_write.h>
#include <stdlib.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <string_view>
#include <utility>

namespace cradle::scene {
namespace {

namespace fs = std::filesystem;

// The sixteen MIMo joints the cubes scene locks, without the robot: prefix.
constexpr std::string_view kLockedJoints[] = {
    "hip_bend1", "hip_lean1",      "hip_rot1",   "hip_bend2",  "hip_lean2",  "hip_rot2",
    "head_tilt", "head_tilt_side", "right_hip1", "right_hip2", "right_hip3", "right_knee",
    "left_hip1", "left_hip2",      "left_hip3",  "left_knee"};

std::string num(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.17g", value);
  return text;
}

// A fresh directory for one test's scene.xml and PNGs.
fs::path make_temp_dir() {
  std::string pattern = (fs::temp_directory_path() / "cradle_world_XXXXXX").string();
  const char* dir = mkdtemp(pattern.data());
  EXPECT_NE(dir, nullptr);
  return fs::path(pattern);
}

// Asset elements of a fragment; generated images are written as PNGs into `dir`.
std::string asset_xml(const WorldFragments& world, const fs::path& dir) {
  std::string xml = world.assets;
  for (const model::TextureAsset& texture : world.textures) {
    xml += "<texture name=\"" + texture.name + "\" type=\"" + texture.type + "\" " +
           texture.attributes;
    for (const auto& [attribute, image] : texture.files) {
      const std::string file = "tex_" + texture.name + "_" + attribute + ".png";
      const int ok = stbi_write_png((dir / file).c_str(), image.width, image.height, 3,
                                    image.rgb.data(), image.width * 3);
      EXPECT_NE(ok, 0) << file;
      xml += " " + attribute + "=\"" + file + "\"";
    }
    xml += "/>\n";
  }
  for (const model::MaterialAsset& material : world.materials) {
    xml += "<material name=\"" + material.name + "\" " +
           (material.texture.empty() ? "" : "texture=\"" + material.texture + "\" ") +
           material.attributes + "/>\n";
  }
  return xml;
}

// Stand-in infant: root mimo_location (free joint) > hip > lower_body > a chain of one hinge per
// locked joint. Its geoms do not collide, so only the scene's own contacts occur.
std::string infant_xml(SceneKind kind) {
  const Placement place = mimo_placement(kind);
  std::string xml = "<body name=\"mimo_location\" pos=\"" + num(place.pos[0]) + " " +
                    num(place.pos[1]) + " " + num(place.pos[2]) + "\" quat=\"" +
                    num(place.quat[0]) + " " + num(place.quat[1]) + " " + num(place.quat[2]) + " " +
                    num(place.quat[3]) + "\">\n<joint type=\"free\" name=\"mimo_location\"/>\n";
  xml +=
      "<body name=\"hip\"><geom type=\"sphere\" size=\"0.048\" contype=\"0\" conaffinity=\"0\"/>\n";
  xml +=
      "<body name=\"lower_body\" pos=\"0 0 0.05\"><geom type=\"sphere\" size=\"0.04\" "
      "contype=\"0\" conaffinity=\"0\"/>\n";
  for (std::string_view joint : kLockedJoints) {
    xml += "<body pos=\"0 0 0.02\"><joint name=\"robot:" + std::string(joint) +
           "\" axis=\"0 1 0\"/><geom type=\"sphere\" size=\"0.01\" "
           "contype=\"0\" conaffinity=\"0\"/>\n";
  }
  for (std::size_t i = 0; i < std::size(kLockedJoints) + 2; ++i) xml += "</body>\n";
  return xml + "</body>\n";
}

struct FreeModel {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct FreeData {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
using TestModel = std::unique_ptr<mjModel, FreeModel>;
using TestData = std::unique_ptr<mjData, FreeData>;

// Writes and compiles the whole test scene: base room + scene fragment + stand-in infant +
// `extra` bodies in the worldbody.
TestModel build_scene(SceneKind kind, const std::string& extra = "",
                      bool mattress_friction_applies = false) {
  const fs::path dir = make_temp_dir();
  const WorldFragments base = base_world();
  const WorldFragments scene = scene_world(kind, mattress_friction_applies);
  const std::string xml =
      "<mujoco model=\"world_test\">\n"
      "<compiler angle=\"degree\" inertiafromgeom=\"true\"/>\n"
      "<option timestep=\"0.005\"/>\n<visual>\n" +
      base_visual() + "</visual>\n<asset>\n" + asset_xml(base, dir) + asset_xml(scene, dir) +
      "</asset>\n<worldbody>\n" + base.worldbody + scene.worldbody + infant_xml(kind) + extra +
      "</worldbody>\n<contact>\n" + base.contact + scene.contact + "</contact>\n<equality>\n" +
      base.equality + scene.equality + "</equality>\n</mujoco>\n";
  const fs::path file = dir / "scene.xml";
  std::ofstream(file) << xml;
  char error[1000] = "";
  TestModel model(mj_loadXML(file.c_str(), nullptr, error, sizeof error));
  EXPECT_NE(model, nullptr) << error << "\n" << xml;
  fs::remove_all(dir);
  return model;
}

int id_of(const mjModel* m, mjtObj type, const char* name) {
  const int id = mj_name2id(m, type, name);
  EXPECT_GE(id, 0) << name;
  return id;
}

// The one contact between the geoms "probe" and "mattress" (a zeroed contact when there is none).
mjContact probe_contact(const mjModel* m, const mjData* d) {
  const int ball = id_of(m, mjOBJ_GEOM, "probe");
  const int mattress = id_of(m, mjOBJ_GEOM, "mattress");
  mjContact found{};
  int n = 0;
  for (int i = 0; i < d->ncon; ++i) {
    const mjContact& c = d->contact[i];
    if ((c.geom1 == ball && c.geom2 == mattress) || (c.geom1 == mattress && c.geom2 == ball)) {
      found = c;
      ++n;
    }
  }
  EXPECT_EQ(n, 1);
  return found;
}

TEST(BaseWorld, CamerasLightsFloorAndTextures) {
  TestModel m = build_scene(SceneKind::kBase);
  ASSERT_NE(m, nullptr);
  TestData d(mj_makeData(m.get()));
  mj_forward(m.get(), d.get());

  // Cameras in the reference order, at their positions.
  const char* names[] = {"corner", "top", "side1", "side2", "closeup"};
  const double positions[][3] = {{3, -3, 3}, {0, 0, 2}, {2, 0, .5}, {0, 2, .5}, {.25, -.25, 1}};
  ASSERT_EQ(m->ncam, 5);
  for (int i = 0; i < 5; ++i) {
    EXPECT_STREQ(mj_id2name(m.get(), mjOBJ_CAMERA, i), names[i]);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(m->cam_pos[3 * i + k], positions[i][k], 1e-12);
  }
  EXPECT_EQ(m->cam_mode[0], mjCAMLIGHT_TARGETBODY);
  EXPECT_EQ(m->cam_mode[4], mjCAMLIGHT_TARGETBODY);
  EXPECT_EQ(m->cam_targetbodyid[0], id_of(m.get(), mjOBJ_BODY, "mimo_location"));
  EXPECT_NEAR(m->cam_fovy[0], 20, 1e-12);
  EXPECT_NEAR(m->cam_fovy[4], 45, 1e-12);
  // A camera looks along its -z: top looks down, side1 toward -x, side2 toward -y.
  const double views[][3] = {{0, 0, -1}, {-1, 0, 0}, {0, -1, 0}};
  for (int i = 1; i <= 3; ++i) {
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(-d->cam_xmat[9 * i + 3 * k + 2], views[i - 1][k], 1e-9) << names[i];
    }
  }

  // Five directional lights; the four corner lights cast no shadow.
  ASSERT_EQ(m->nlight, 5);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(m->light_directional[i], 1);
  EXPECT_EQ(m->light_castshadow[0], 1);
  for (int i = 1; i < 5; ++i) EXPECT_EQ(m->light_castshadow[i], 0);
  EXPECT_NEAR(m->light_ambient[0], 0.2, 1e-6);
  EXPECT_NEAR(m->light_specular[3 * 1], 0.3, 1e-6);

  // The physical floor is the invisible plane at z = 0; the visible floor and rug are below it.
  const int floor = id_of(m.get(), mjOBJ_GEOM, "transparent");
  EXPECT_EQ(m->geom_type[floor], mjGEOM_PLANE);
  EXPECT_NEAR(d->geom_xpos[3 * floor + 2], 0, 1e-12);
  EXPECT_NEAR(m->geom_size[3 * floor], 2, 1e-12);
  EXPECT_NEAR(m->mat_rgba[4 * m->geom_matid[floor] + 3], 0, 1e-12);
  EXPECT_NEAR(d->geom_xpos[3 * id_of(m.get(), mjOBJ_GEOM, "floor") + 2], -0.01, 1e-12);
  const int rug = id_of(m.get(), mjOBJ_GEOM, "rug");
  EXPECT_EQ(m->geom_type[rug], mjGEOM_CYLINDER);
  EXPECT_NEAR(m->geom_size[3 * rug], 1, 1e-12);
  EXPECT_NEAR(m->geom_size[3 * rug + 1], 0.0045, 1e-12);
  EXPECT_NEAR(d->geom_xpos[3 * rug + 2], -0.005, 1e-12);

  // Visual settings, and a texture budget far below the reference's 1.46 GB.
  EXPECT_NEAR(m->vis.map.force, 0.1, 1e-6);
  EXPECT_NEAR(m->vis.map.fogend, 10, 1e-6);
  EXPECT_NEAR(m->vis.map.shadowclip, 3, 1e-6);
  EXPECT_EQ(m->vis.headlight.active, 0);
  EXPECT_EQ(m->vis.quality.shadowsize, 0);
  EXPECT_LE(m->ntexdata, 4 << 20);
  EXPECT_GE(id_of(m.get(), mjOBJ_TEXTURE, "texrug"), 0);
}

TEST(CribWorld, MattressWeldAndReferenceFriction) {
  // A probe ball with MIMo's skin contact parameters, dropped onto the mattress.
  const std::string probe =
      "<body name=\"probe\" pos=\"0.2 0 0.3\"><freejoint/><geom name=\"probe\" type=\"sphere\" "
      "size=\"0.02\" solref=\"0.005 1\" solimp=\"0.95 0.99 0.001 0.5 1\"/></body>\n";
  TestModel m = build_scene(SceneKind::kCrib, probe);
  ASSERT_NE(m, nullptr);
  TestData d(mj_makeData(m.get()));
  mj_forward(m.get(), d.get());

  // Mattress top at 0.25 m; every crib body is static (welded to the world, no joints).
  const int mattress = id_of(m.get(), mjOBJ_GEOM, "mattress");
  EXPECT_NEAR(d->geom_xpos[3 * mattress + 2] + m->geom_size[3 * mattress + 2], 0.25, 1e-12);
  EXPECT_NEAR(d->geom_xpos[3 * mattress], -0.05, 1e-12);
  EXPECT_NEAR(m->geom_friction[3 * mattress], 0.1, 1e-12);
  EXPECT_EQ(m->geom_priority[mattress], 0);  // as the reference's
  for (const char* name :
       {"crib", "crib_feet", "crib_head", "crib_left", "crib_right", "crib_base"}) {
    const int body = id_of(m.get(), mjOBJ_BODY, name);
    EXPECT_EQ(m->body_weldid[body], 0) << name;
    EXPECT_EQ(m->body_jntnum[body], 0) << name;
  }
  // Rails: feet end at x = 0.5, side rails span 1.12 m along x at y = ±0.425.
  const int left = id_of(m.get(), mjOBJ_BODY, "crib_left");
  const int rail = m->body_geomadr[left];
  EXPECT_NEAR(d->geom_xpos[3 * rail + 1], 0.425, 1e-12);
  EXPECT_NEAR(std::abs(d->geom_xmat[9 * rail + 2]), 1, 1e-9);  // rail's long axis (z) along x

  // The lower_body weld, active at load.
  ASSERT_EQ(m->neq, 1);
  EXPECT_EQ(m->eq_type[0], mjEQ_WELD);
  EXPECT_EQ(m->eq_obj1id[0], id_of(m.get(), mjOBJ_BODY, "lower_body"));
  EXPECT_EQ(m->eq_active[0], 1);
  const int lower = m->eq_obj1id[0];
  const std::array<double, 3> start{d->xpos[3 * lower], d->xpos[3 * lower + 1],
                                    d->xpos[3 * lower + 2]};

  // After the probe lands, its contact with the mattress takes the larger friction (the probe's
  // default 1), as in the reference; solver parameters are the equal-priority mix.
  for (int i = 0; i < 100; ++i) mj_step(m.get(), d.get());
  const mjContact c = probe_contact(m.get(), d.get());
  EXPECT_NEAR(c.friction[0], 1, 1e-12);
  EXPECT_NEAR(c.friction[2], 0.005, 1e-12);
  EXPECT_NEAR(c.solref[0], 0.0125, 1e-12);
  EXPECT_NEAR(d->xpos[3 * id_of(m.get(), mjOBJ_BODY, "probe") + 2], 0.27, 2e-3);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(d->xpos[3 * lower + k], start[k], 1e-3);
}

TEST(CribWorld, OptInMattressFrictionAppliesToMimo) {
  // mattress_friction_applies: contact priority makes the mattress's 0.1 apply; same stiffness.
  const std::string probe =
      "<body name=\"probe\" pos=\"0.2 0 0.3\"><freejoint/><geom name=\"probe\" type=\"sphere\" "
      "size=\"0.02\" solref=\"0.005 1\" solimp=\"0.95 0.99 0.001 0.5 1\"/></body>\n";
  TestModel m = build_scene(SceneKind::kCrib, probe, /*mattress_friction_applies=*/true);
  ASSERT_NE(m, nullptr);
  TestData d(mj_makeData(m.get()));
  EXPECT_EQ(m->geom_priority[id_of(m.get(), mjOBJ_GEOM, "mattress")], 1);
  for (int i = 0; i < 100; ++i) mj_step(m.get(), d.get());
  const mjContact c = probe_contact(m.get(), d.get());
  EXPECT_NEAR(c.friction[0], 0.1, 1e-12);
  EXPECT_NEAR(c.friction[2], 0.0005, 1e-12);
  EXPECT_NEAR(c.solref[0], 0.0125, 1e-12);
  EXPECT_NEAR(d->xpos[3 * id_of(m.get(), mjOBJ_BODY, "probe") + 2], 0.27, 2e-3);
}

TEST(CribWorld, MattressSolverParamsMatchReferenceMix) {
  // Without priorities MuJoCo 2.2.2 averages solref/solimp; the opt-in priority mattress declares
  // exactly what a default geom and a skin geom average to, so contact stiffness stays the
  // reference's.
  const char* xml =
      "<mujoco><worldbody><geom name=\"board\" type=\"box\" size=\"1 1 0.1\"/>"
      "<body pos=\"0 0 0.115\"><freejoint/><geom name=\"skin\" type=\"sphere\" size=\"0.02\" "
      "solref=\"0.005 1\" solimp=\"0.95 0.99 0.001 0.5 1\"/></body></worldbody></mujoco>";
  const fs::path dir = make_temp_dir();
  std::ofstream(dir / "mix.xml") << xml;
  char error[1000] = "";
  TestModel mix(mj_loadXML((dir / "mix.xml").c_str(), nullptr, error, sizeof error));
  fs::remove_all(dir);
  ASSERT_NE(mix, nullptr) << error;
  TestData d(mj_makeData(mix.get()));
  mj_forward(mix.get(), d.get());
  ASSERT_EQ(d->ncon, 1);

  TestModel crib = build_scene(SceneKind::kCrib, "", /*mattress_friction_applies=*/true);
  ASSERT_NE(crib, nullptr);
  const int mattress = id_of(crib.get(), mjOBJ_GEOM, "mattress");
  for (int k = 0; k < mjNREF; ++k) {
    EXPECT_NEAR(crib->geom_solref[mjNREF * mattress + k], d->contact[0].solref[k], 1e-12);
  }
  for (int k = 0; k < mjNIMP; ++k) {
    EXPECT_NEAR(crib->geom_solimp[mjNIMP * mattress + k], d->contact[0].solimp[k], 1e-12);
  }
}

TEST(CubesWorld, ToysLocksAndSettling) {
  TestModel m = build_scene(SceneKind::kCubes);
  ASSERT_NE(m, nullptr);
  TestData d(mj_makeData(m.get()));

  // Sixteen free toys besides MIMo's root; mass = 200 kg/m^3 x volume.
  const int root = id_of(m.get(), mjOBJ_BODY, "mimo_location");
  int toys = 0;
  for (int j = 0; j < m->njnt; ++j) {
    if (m->jnt_type[j] != mjJNT_FREE || m->jnt_bodyid[j] == root) continue;
    ++toys;
    const int body = m->jnt_bodyid[j];
    const int geom = m->body_geomadr[body];
    const double* size = &m->geom_size[3 * geom];
    const double volume = m->geom_type[geom] == mjGEOM_BOX
                              ? 8 * size[0] * size[1] * size[2]
                              : 4.0 / 3.0 * M_PI * size[0] * size[0] * size[0];
    EXPECT_NEAR(m->body_mass[body], 200 * volume, 1e-9) << mj_id2name(m.get(), mjOBJ_BODY, body);
  }
  EXPECT_EQ(toys, 16);
  EXPECT_NEAR(m->body_mass[id_of(m.get(), mjOBJ_BODY, "red_cube")], 0.0432, 1e-12);
  EXPECT_NEAR(m->body_mass[id_of(m.get(), mjOBJ_BODY, "red_sphere")], 800.0 / 3.0 * M_PI * 1e-3,
              1e-12);
  const int bridge = id_of(m.get(), mjOBJ_BODY, "castle_bridge");
  EXPECT_NEAR(m->body_mass[bridge], 200 * 8 * 0.045 * 0.125 * 0.025, 1e-12);
  EXPECT_NEAR(m->body_quat[4 * bridge], std::cos(M_PI / 8), 1e-9);  // 45 degree yaw

  // Seventeen equalities active at load: the root weld and the sixteen locks (radians).
  ASSERT_EQ(m->neq, 17);
  EXPECT_EQ(m->eq_type[0], mjEQ_WELD);
  EXPECT_EQ(m->eq_obj1id[0], root);
  const std::pair<const char*, double> expected[] = {
      {"robot:hip_bend1", 0.532},  {"robot:hip_bend2", 0.532},  {"robot:head_tilt", 0.4},
      {"robot:right_hip1", -1.22}, {"robot:right_hip2", -0.70}, {"robot:right_hip3", 0.538},
      {"robot:right_knee", -1.45}, {"robot:left_hip1", -1.41},  {"robot:left_hip2", -0.823},
      {"robot:left_hip3", 0.612},  {"robot:left_knee", -2.14},  {"robot:hip_rot1", 0},
      {"robot:head_tilt_side", 0}};
  int locks = 0;
  for (int e = 0; e < m->neq; ++e) {
    EXPECT_EQ(m->eq_active[e], 1);
    if (m->eq_type[e] != mjEQ_JOINT) continue;
    ++locks;
    EXPECT_EQ(m->eq_obj2id[e], -1);
    const char* joint = mj_id2name(m.get(), mjOBJ_JOINT, m->eq_obj1id[e]);
    for (const auto& [name, angle] : expected) {
      if (std::string_view(joint) == name) {
        EXPECT_NEAR(m->eq_data[mjNEQDATA * e], angle, 1e-12) << name;
      }
    }
  }
  EXPECT_EQ(locks, 16);

  // One simulated second: finite, toys on (or above) the floor, joints held at the lock angles.
  for (int i = 0; i < 200; ++i) mj_step(m.get(), d.get());
  for (int i = 0; i < m->nq; ++i) ASSERT_TRUE(std::isfinite(d->qpos[i])) << i;
  for (int j = 0; j < m->njnt; ++j) {
    if (m->jnt_type[j] != mjJNT_FREE || m->jnt_bodyid[j] == root) continue;
    const int body = m->jnt_bodyid[j];
    const int geom = m->body_geomadr[body];
    const double* size = &m->geom_size[3 * geom];
    const double low =
        m->geom_type[geom] == mjGEOM_BOX ? std::min({size[0], size[1], size[2]}) : size[0];
    EXPECT_GE(d->xpos[3 * body + 2], low - 2e-3) << mj_id2name(m.get(), mjOBJ_BODY, body);
    EXPECT_LT(std::hypot(d->xpos[3 * body], d->xpos[3 * body + 1]), 2.0);
  }
  const int knee = id_of(m.get(), mjOBJ_JOINT, "robot:left_knee");
  EXPECT_NEAR(d->qpos[m->jnt_qposadr[knee]], -2.14, 0.02);
}

TEST(Placement, UnitQuaternionsAndSupinePose) {
  for (SceneKind kind : {SceneKind::kBase, SceneKind::kCrib, SceneKind::kCubes}) {
    const Placement place = mimo_placement(kind);
    double norm = 0;
    for (double q : place.quat) norm += q * q;
    EXPECT_NEAR(std::sqrt(norm), 1, 1e-5);
  }
  EXPECT_NEAR(mimo_placement(SceneKind::kBase).pos[2], 0.1, 1e-12);
  EXPECT_NEAR(mimo_placement(SceneKind::kCrib).pos[2], 0.3, 1e-12);
  EXPECT_NEAR(mimo_placement(SceneKind::kCubes).pos[2], 0.0467196, 1e-12);
  // Lying supine: the spine (+z) points to world -x, the front (+x) up.
  for (SceneKind kind : {SceneKind::kBase, SceneKind::kCrib}) {
    const Placement place = mimo_placement(kind);
    const mjtNum up[3] = {0, 0, 1};
    const mjtNum front[3] = {1, 0, 0};
    mjtNum spine[3];
    mjtNum facing[3];
    mju_rotVecQuat(spine, up, place.quat.data());
    mju_rotVecQuat(facing, front, place.quat.data());
    EXPECT_NEAR(spine[0], -1, 1e-12);
    EXPECT_NEAR(facing[2], 1, 1e-12);
  }
  // Sitting in cubes: a recline of about 55.4 degrees about -y.
  const double angle = 2 * std::acos(mimo_placement(SceneKind::kCubes).quat[0]);
  EXPECT_NEAR(angle * 180 / M_PI, 55.4, 0.1);
}

TEST(SceneWorld, BaseAddsNothing) {
  const WorldFragments none = scene_world(SceneKind::kBase);
  EXPECT_TRUE(none.textures.empty() && none.materials.empty() && none.assets.empty());
  EXPECT_TRUE(none.worldbody.empty() && none.contact.empty() && none.equality.empty());
}

}  // namespace
}  // namespace cradle::scene

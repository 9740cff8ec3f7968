#include "sami/scene.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "core/xml.h"

namespace cradle::sami {
namespace {

// MuJoCo's writer on `m` (whose sizes must be those of the last MJCF MuJoCo loaded): the text.
std::string saved_xml(const mjModel* m) {
  std::string path = (std::filesystem::temp_directory_path() / "cradle_sami_XXXXXX.xml").string();
  const int fd = mkstemps(path.data(), 4);
  if (fd < 0) throw std::runtime_error("cannot create a temporary file for the SaMI scene");
  close(fd);
  char error[1024] = "";
  const int ok = mj_saveLastXML(path.c_str(), m, error, sizeof(error));
  std::stringstream text;
  text << std::ifstream(path).rdbuf();
  std::error_code ec;
  std::filesystem::remove(path, ec);
  if (!ok) throw std::runtime_error(std::string("MuJoCo could not write the SaMI scene: ") + error);
  return text.str();
}

std::string inertial(const mjModel* m, int b) {
  return "<inertial pos=\"" +
         nums({m->body_ipos[3 * b], m->body_ipos[3 * b + 1], m->body_ipos[3 * b + 2]}) +
         "\" quat=\"" +
         nums({m->body_iquat[4 * b], m->body_iquat[4 * b + 1], m->body_iquat[4 * b + 2],
               m->body_iquat[4 * b + 3]}) +
         "\" mass=\"" + num(m->body_mass[b]) + "\" diaginertia=\"" +
         nums({m->body_inertia[3 * b], m->body_inertia[3 * b + 1], m->body_inertia[3 * b + 2]}) +
         "\"/>";
}

// The value of attribute `name` in one element's line ("" when absent).
std::string attribute(const std::string& line, const std::string& name) {
  const size_t at = line.find(" " + name + "=\"");
  if (at == std::string::npos) return "";
  const size_t value = at + name.size() + 3;
  return line.substr(value, line.find('"', value) - value);
}

// The index of m's pair between geoms a and b (either way round), or -1.
int pair_of(const mjModel* m, int a, int b) {
  for (int p = 0; p < m->npair; ++p) {
    const int g1 = m->pair_geom1[p], g2 = m->pair_geom2[p];
    if ((g1 == a && g2 == b) || (g1 == b && g2 == a)) return p;
  }
  return -1;
}

// A <pair> line with the friction of the model's pair between the same two geoms. MuJoCo 2.2.2
// copies pair values back by index into pairs that the compiler had sorted, so the writer's
// friction may belong to another pair.
std::string with_pair_friction(std::string line, const mjModel* m) {
  const int a = mj_name2id(m, mjOBJ_GEOM, attribute(line, "geom1").c_str());
  const int b = mj_name2id(m, mjOBJ_GEOM, attribute(line, "geom2").c_str());
  const int p = pair_of(m, a, b);
  if (p < 0) return line;
  const std::string friction =
      nums({m->pair_friction[5 * p], m->pair_friction[5 * p + 1], m->pair_friction[5 * p + 2],
            m->pair_friction[5 * p + 3], m->pair_friction[5 * p + 4]});
  const size_t at = line.find(" friction=\"");
  if (at == std::string::npos) {
    line.insert(line.rfind("/>"), " friction=\"" + friction + "\"");
  } else {
    const size_t value = at + 11;
    line.replace(value, line.find('"', value) - value, friction);
  }
  return line;
}

// The writer's text with every <pair> given its own friction, the compiler told to take inertias
// from the file and every body given the model's exact inertial (replacing the writer's where it
// wrote one). Bodies appear in the text in id order (depth first), so the k-th <body> is body k.
std::string with_inertials(const std::string& xml, const mjModel* m) {
  std::istringstream in(xml);
  std::string line, out;
  int body = 0;
  bool drop_inertial = false;
  while (std::getline(in, line)) {
    const size_t first = line.find_first_not_of(' ');
    const std::string_view t =
        first == std::string::npos ? std::string_view() : std::string_view(line).substr(first);
    if (drop_inertial && t.starts_with("<inertial")) {
      drop_inertial = false;
      continue;
    }
    drop_inertial = false;
    if (t.starts_with("<compiler")) {
      const size_t at = line.find("inertiafromgeom=\"");
      if (at == std::string::npos) {
        line.insert(first + 9, " inertiafromgeom=\"false\"");
      } else {
        const size_t value = at + 17;
        line.replace(value, line.find('"', value) - value, "false");
      }
    }
    if (t.starts_with("<pair")) line = with_pair_friction(line, m);
    if (!t.starts_with("<body") || m->body_mass[body + 1] == 0) {
      body += t.starts_with("<body");
      out += line + "\n";
      continue;
    }
    ++body;
    const std::string indent(first + 2, ' ');
    if (t.ends_with("/>")) {  // a body with no children: open it for the inertial
      line.erase(line.size() - 2);
      out +=
          line + ">\n" + indent + inertial(m, body) + "\n" + std::string(first, ' ') + "</body>\n";
      continue;
    }
    out += line + "\n" + indent + inertial(m, body) + "\n";
    drop_inertial = true;
  }
  return out;
}

// Empty when a and b agree to the tolerance, else the first difference ("[i] a vs b").
std::string difference(const mjtNum* a, const mjtNum* b, int n, double tolerance) {
  for (int i = 0; i < n; ++i) {
    if (std::abs(a[i] - b[i]) > tolerance * std::max(1.0, std::abs(b[i]))) {
      return "[" + std::to_string(i) + "] " + num(a[i]) + " vs " + num(b[i]);
    }
  }
  return "";
}

}  // namespace

std::string scene_xml(const SamiEnv& env) {
  const mjModel* m = env.model();
  // The masked actuators act with gear 0 (the env multiplies their action by 0).
  mjModel header = *m;
  std::vector<mjtNum> gear(m->actuator_gear, m->actuator_gear + 6 * m->nu);
  const auto mask = env.action_mask();
  for (size_t a = 0; a < mask.size() && static_cast<int>(a) < m->nu; ++a) {
    if (mask[a] == 0) std::fill_n(gear.begin() + 6 * a, 6, 0.0);
  }
  header.actuator_gear = gear.data();
  // Loading the robot makes it MuJoCo's last XML, the one the writer fills from `header`.
  const ModelPtr loaded = compile_robot(env.spec().robot);
  const std::string xml = with_inertials(saved_xml(&header), m);

  // The written text must compile to the env's parameters (to the writer's 6 digits).
  const ModelPtr back = compile_xml(xml);
  const mjModel* b = back.get();
  const auto check = [&](const std::string& difference, const char* what) {
    if (!difference.empty()) {
      throw std::logic_error(std::string("the written SaMI scene does not compile to the env's ") +
                             what + difference);
    }
  };
  check(b->nbody == m->nbody && b->ngeom == m->ngeom && b->nv == m->nv && b->nu == m->nu &&
                b->npair == m->npair
            ? ""
            : " (counts differ)",
        "sizes");
  check(difference(b->body_mass, m->body_mass, m->nbody, 1e-12), "body_mass");
  check(difference(b->body_inertia, m->body_inertia, 3 * m->nbody, 1e-12), "body_inertia");
  check(difference(b->dof_damping, m->dof_damping, m->nv, 1e-5), "dof_damping");
  check(difference(b->geom_size, m->geom_size, 3 * m->ngeom, 1e-5), "geom_size");
  check(difference(b->geom_friction, m->geom_friction, 3 * m->ngeom, 1e-5), "geom_friction");
  // Pairs between the same two bodies may compile in either order: match them by their geoms.
  for (int p = 0; p < b->npair; ++p) {
    const int q = pair_of(m, b->pair_geom1[p], b->pair_geom2[p]);
    check(q < 0 ? " (a pair is missing)"
                : difference(b->pair_friction + 5 * p, m->pair_friction + 5 * q, 5, 1e-5),
          "pair_friction");
  }
  check(difference(b->actuator_gear, gear.data(), 6 * m->nu, 1e-5), "actuator_gear");
  return xml;
}

}  // namespace cradle::sami

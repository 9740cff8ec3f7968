// `_cradle.SamiEnv`: the SaMI env family (src/sami/) for Python; cradle/sami.py wraps it in
// Gymnasium's Env protocol.
#include <memory>
#include <string>

#include "envs/action_check.h"
#include "python/common.h"
#include "sami/env.h"
#include "sami/render.h"

namespace cradle::python {
namespace {

struct PySamiEnv {
  std::unique_ptr<sami::SamiEnv> env;
  std::unique_ptr<sami::Renderer> renderer;
};

// Observation keys as fresh numpy arrays in the spec's dtype.
py::dict observation(const sami::SamiEnv& env) {
  py::dict out;
  const sami::Spec& spec = env.spec();
  for (const sami::ObsKey& key : spec.keys) {
    const auto values = env.observation(key);
    if (spec.obs_dtype == DType::kFloat32) {
      py::array_t<float> a(key.size);
      for (int i = 0; i < key.size; ++i) a.mutable_at(i) = static_cast<float>(values[i]);
      out[key.name.c_str()] = a;
    } else {
      py::array_t<double> a(key.size);
      for (int i = 0; i < key.size; ++i) a.mutable_at(i) = values[i];
      out[key.name.c_str()] = a;
    }
  }
  return out;
}

// The hidden parameters and labels (analysis only).
py::dict info(const sami::SamiEnv& env) {
  const sami::Info& i = env.info();
  py::dict d;
  d["steps"] = i.steps;
  d["task_set"] = i.task_set;
  if (env.spec().id == sami::EnvId::kPandaPush) {
    d["friction"] = i.friction;
    d["cube_mass"] = i.mass;
    d["is_success"] = i.is_success;
    d["skill"] = std::string(sami::skill_name(i.skill));
    d["episode_skill"] = std::string(sami::skill_name(i.episode_skill));
  } else {
    d["mass"] = i.mass;
    d["damping"] = i.damping;
    d["crippled"] = py::cast(i.crippled);
    d["masked"] = i.masked;
    d["x_velocity"] = i.x_velocity;
  }
  return d;
}

}  // namespace

void bind_sami(py::module_& m) {
  bind_sami_learn(m);
  m.def("sami_env_names", [] {
    py::list names;
    for (sami::EnvId id : sami::all_envs()) names.append(std::string(sami::env_name(id)));
    return names;
  });
  py::class_<PySamiEnv>(m, "SamiEnv", "A SaMI env (use cradle.sami.make).")
      .def(py::init([](const std::string& name, const std::string& split, std::uint64_t seed,
                       bool contact_forces) {
             return PySamiEnv{sami::make_env(name, split, seed, {.contact_forces = contact_forces}),
                              nullptr};
           }),
           py::arg("name"), py::arg("split"), py::arg("seed"), py::arg("contact_forces") = false)
      .def_property_readonly("name", [](const PySamiEnv& e) { return e.env->spec().name; })
      .def_property_readonly("horizon", [](const PySamiEnv& e) { return e.env->spec().horizon; })
      .def_property_readonly("dt", [](const PySamiEnv& e) { return e.env->spec().dt; })
      .def_property_readonly(
          "action_space",
          [](const PySamiEnv& e) { return box_tuple(e.env->spec().action_space()); })
      .def_property_readonly(
          "observation_space",
          [](const PySamiEnv& e) { return space_list(e.env->spec().observation_space()); })
      .def(
          "reset",
          [](PySamiEnv& e, std::optional<std::uint64_t> seed) {
            e.env->reset(seed);
            return py::make_tuple(observation(*e.env), info(*e.env));
          },
          py::arg("seed") = py::none())
      .def("step",
           [](PySamiEnv& e, py::array_t<double, py::array::c_style | py::array::forcecast> a) {
             const std::span<const double> action(a.data(), static_cast<size_t>(a.size()));
             // MuJoCo would zero a non-finite control and hand back NaN observations.
             envs::check_finite_actions(action);
             const sami::StepResult r = e.env->step(action);
             return py::make_tuple(observation(*e.env), r.reward, r.terminated, r.truncated,
                                   info(*e.env));
           })
      .def(
          "render",
          [](PySamiEnv& e, int width, int height) {
            if (!e.renderer || e.renderer->width() != width || e.renderer->height() != height) {
              e.renderer = std::make_unique<sami::Renderer>(*e.env, width, height);
            }
            py::array_t<std::uint8_t> rgb({height, width, 3});
            e.renderer->render(*e.env, std::span<std::uint8_t>(rgb.mutable_data(), rgb.size()));
            return rgb;
          },
          py::arg("width") = 320, py::arg("height") = 240);
}

}  // namespace cradle::python

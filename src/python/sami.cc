// `_cradle.SamiEnv`: the SaMI env family (src/sami/) for Python; cradle/sami.py wraps it in
// Gymnasium's Env protocol.
#include <algorithm>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "envs/action_check.h"
#include "python/common.h"
#include "sami/env.h"
#include "sami/render.h"

namespace cradle::python {
namespace {

struct PySamiEnv {
  std::shared_ptr<sami::SamiEnv> env;  // shared with the model and data views
  std::unique_ptr<sami::Renderer> renderer;
};

// Read-only numpy views of the env's MuJoCo model (its private copy: this episode's hidden
// parameters) and data (the current state). Each array keeps the env alive, so a view outlives
// the Python env without dangling; the env overwrites the values at its next reset or step.
struct SamiModelView {
  std::shared_ptr<sami::SamiEnv> env;
  const mjModel* m() const { return env->model(); }
};
struct SamiDataView {
  std::shared_ptr<sami::SamiEnv> env;
  const mjModel* m() const { return env->model(); }
  const mjData* d() const { return env->data(); }
};

template <typename T>
py::array read_only(const T* data, std::vector<py::ssize_t> shape,
                    const std::shared_ptr<sami::SamiEnv>& env) {
  auto* holder = new std::shared_ptr<sami::SamiEnv>(env);
  const py::capsule owner(holder,
                          [](void* h) { delete static_cast<std::shared_ptr<sami::SamiEnv>*>(h); });
  py::array out(py::dtype::of<T>(), std::move(shape), {}, data, owner);
  py::detail::array_proxy(out.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return out;
}

py::list names(const mjModel* m, mjtObj type, int n) {
  py::list out;
  for (int i = 0; i < n; ++i) {
    const char* name = mj_id2name(m, type, i);
    out.append(name ? name : "");
  }
  return out;
}

void bind_views(py::module_& m) {
  using M = SamiModelView;
  py::class_<M>(m, "SamiModel", "Read-only views of a SaMI env's MuJoCo model.")
      .def_property_readonly("nq", [](const M& v) { return v.m()->nq; })
      .def_property_readonly("nv", [](const M& v) { return v.m()->nv; })
      .def_property_readonly("nu", [](const M& v) { return v.m()->nu; })
      .def_property_readonly("nbody", [](const M& v) { return v.m()->nbody; })
      .def_property_readonly("njnt", [](const M& v) { return v.m()->njnt; })
      .def_property_readonly("ngeom", [](const M& v) { return v.m()->ngeom; })
      .def_property_readonly("npair", [](const M& v) { return v.m()->npair; })
      .def_property_readonly("timestep", [](const M& v) { return v.m()->opt.timestep; })
      .def_property_readonly("body_names",
                             [](const M& v) { return names(v.m(), mjOBJ_BODY, v.m()->nbody); })
      .def_property_readonly("joint_names",
                             [](const M& v) { return names(v.m(), mjOBJ_JOINT, v.m()->njnt); })
      .def_property_readonly("geom_names",
                             [](const M& v) { return names(v.m(), mjOBJ_GEOM, v.m()->ngeom); })
      .def_property_readonly("actuator_names",
                             [](const M& v) { return names(v.m(), mjOBJ_ACTUATOR, v.m()->nu); })
      .def_property_readonly(
          "body_mass",
          [](const M& v) { return read_only(v.m()->body_mass, {v.m()->nbody}, v.env); })
      .def_property_readonly("body_inertia",
                             [](const M& v) {
                               return read_only(v.m()->body_inertia, {v.m()->nbody, 3}, v.env);
                             })
      .def_property_readonly(
          "dof_damping",
          [](const M& v) { return read_only(v.m()->dof_damping, {v.m()->nv}, v.env); })
      .def_property_readonly("geom_size",
                             [](const M& v) {
                               return read_only(v.m()->geom_size, {v.m()->ngeom, 3}, v.env);
                             })
      .def_property_readonly("geom_friction",
                             [](const M& v) {
                               return read_only(v.m()->geom_friction, {v.m()->ngeom, 3}, v.env);
                             })
      .def_property_readonly("geom_rgba",
                             [](const M& v) {
                               return read_only(v.m()->geom_rgba, {v.m()->ngeom, 4}, v.env);
                             })
      .def_property_readonly("pair_friction",
                             [](const M& v) {
                               return read_only(v.m()->pair_friction, {v.m()->npair, 5}, v.env);
                             })
      .def_property_readonly("actuator_gear",
                             [](const M& v) {
                               return read_only(v.m()->actuator_gear, {v.m()->nu, 6}, v.env);
                             })
      .def_property_readonly("actuator_ctrlrange",
                             [](const M& v) {
                               return read_only(v.m()->actuator_ctrlrange, {v.m()->nu, 2}, v.env);
                             })
      .def_property_readonly("jnt_range",
                             [](const M& v) {
                               return read_only(v.m()->jnt_range, {v.m()->njnt, 2}, v.env);
                             })
      .def_property_readonly(
          "qpos0", [](const M& v) { return read_only(v.m()->qpos0, {v.m()->nq}, v.env); });

  using D = SamiDataView;
  py::class_<D>(m, "SamiData", "Read-only views of a SaMI env's mjData (they follow the env).")
      .def_property_readonly("time", [](const D& v) { return v.d()->time; })
      .def_property_readonly("ncon", [](const D& v) { return v.d()->ncon; })
      .def_property_readonly("qpos",
                             [](const D& v) { return read_only(v.d()->qpos, {v.m()->nq}, v.env); })
      .def_property_readonly("qvel",
                             [](const D& v) { return read_only(v.d()->qvel, {v.m()->nv}, v.env); })
      .def_property_readonly("qacc",
                             [](const D& v) { return read_only(v.d()->qacc, {v.m()->nv}, v.env); })
      .def_property_readonly("ctrl",
                             [](const D& v) { return read_only(v.d()->ctrl, {v.m()->nu}, v.env); })
      .def_property_readonly("xpos",
                             [](const D& v) {
                               return read_only(v.d()->xpos, {v.m()->nbody, 3}, v.env);
                             })
      .def_property_readonly("xquat",
                             [](const D& v) {
                               return read_only(v.d()->xquat, {v.m()->nbody, 4}, v.env);
                             })
      .def_property_readonly("geom_xpos",
                             [](const D& v) {
                               return read_only(v.d()->geom_xpos, {v.m()->ngeom, 3}, v.env);
                             })
      .def_property_readonly("cfrc_ext", [](const D& v) {
        return read_only(v.d()->cfrc_ext, {v.m()->nbody, 6}, v.env);
      });
}

// Observation keys as fresh float32 numpy arrays (the reference's dtype).
py::dict observation(const sami::SamiEnv& env) {
  py::dict out;
  for (const sami::ObsKey& key : env.spec().keys) {
    const auto values = env.observation(key);
    py::array_t<float> a(key.size);
    std::copy(values.begin(), values.end(), a.mutable_data());
    out[key.name.c_str()] = a;
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

py::object sami_model_view(std::shared_ptr<sami::SamiEnv> env) {
  return py::cast(SamiModelView{std::move(env)});
}

py::object sami_data_view(std::shared_ptr<sami::SamiEnv> env) {
  return py::cast(SamiDataView{std::move(env)});
}

py::dict sami_info(const sami::SamiEnv& env) { return info(env); }

void bind_sami(py::module_& m) {
  bind_sami_learn(m);
  bind_views(m);
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
      .def_property_readonly("model", [](const PySamiEnv& e) { return SamiModelView{e.env}; })
      .def_property_readonly("data", [](const PySamiEnv& e) { return SamiDataView{e.env}; })
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

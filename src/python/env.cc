// The single BabyBench env for Python (`_cradle.Env`), plus read-only views of its MuJoCo model
// and data, proprioception and skin (the attributes the reference documents: env.model.nu,
// env.model.actuator(i).name, env.proprioception.joint_names, env.touch.sensor_positions).
//
// Buffers: every Python object that points into C++ memory (observation views, model and data
// arrays) holds a shared_ptr to what owns that memory, so the memory outlives the Python object
// and no reference cycle through the env is formed.
#include <mujoco/mujoco.h>

#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include "core/error.h"
#include "envs/babybench.h"
#include "python/common.h"
#include "senses/vision.h"

namespace cradle::python {
namespace {

// A capsule that keeps `owner` alive for as long as a numpy view uses it as its base.
py::capsule keep_alive(std::shared_ptr<const void> owner) {
  auto* holder = new std::shared_ptr<const void>(std::move(owner));
  return py::capsule(holder, [](void* h) { delete static_cast<std::shared_ptr<const void>*>(h); });
}

// A read-only float64 view of `rows` x `cols` values (cols = 0: 1-D).
py::array view_matrix(const double* data, py::ssize_t rows, py::ssize_t cols, py::handle owner) {
  if (cols == 0) return view_doubles(data, rows, owner);
  py::array out(py::dtype::of<double>(), {rows, cols}, {}, data, owner);
  py::detail::array_proxy(out.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return out;
}

// One named MuJoCo object (model.actuator(i), model.joint("name"), ...).
struct Named {
  int id = -1;
  std::string name;
};

using IdOrName = std::variant<int, std::string>;

// Looks up object `ref` of type `type` (count `n`): an index in [0, n) or a name.
Named named(const mjModel* m, mjtObj type, int n, const IdOrName& ref, const char* what) {
  int id = -1;
  if (const int* i = std::get_if<int>(&ref)) {
    id = *i < 0 ? *i + n : *i;  // negative indices count from the end, as in Python
    if (id < 0 || id >= n) {
      throw py::index_error(std::string(what) + " index " + std::to_string(*i) +
                            " out of range [0, " + std::to_string(n) + ")");
    }
  } else {
    const std::string& name = std::get<std::string>(ref);
    id = mj_name2id(m, type, name.c_str());
    if (id < 0) throw py::key_error(std::string("no ") + what + " named '" + name + "'");
  }
  const char* name = mj_id2name(m, type, id);
  return {id, name ? name : ""};
}

// env.model: a compiled mjModel (a BabyBench config's, shared by its envs; a MIMo sample env's),
// kept alive by `holder`.
struct ModelView {
  std::shared_ptr<const void> holder;
  const mjModel* model = nullptr;
  const mjModel* m() const { return model; }
  py::capsule owner() const { return keep_alive(holder); }
};

// env.data: an env's own mjData (read-only from Python), kept alive by `holder`.
struct DataView {
  std::shared_ptr<const void> holder;
  const mjModel* model = nullptr;
  const mjData* data = nullptr;
  const mjModel* m() const { return model; }
  const mjData* d() const { return data; }
  py::capsule owner() const { return keep_alive(holder); }
};

// env.proprioception.
struct ProprioView {
  std::shared_ptr<const envs::BabyBenchEnv> env;
};

// env.touch (None when touch is off).
struct TouchView {
  std::shared_ptr<const envs::BabyBenchEnv> env;
  const senses::Touch& touch() const { return *env->touch(); }
};

}  // namespace

// The env behind cradle.BabyBenchEnv. copy = true: reset/step return fresh arrays; false: they
// return read-only views of the env's buffers, overwritten by the next reset/step.
class PyEnv {
 public:
  PyEnv(const Config& config, bool training, std::uint64_t seed, bool copy) : copy_(copy) {
    py::gil_scoped_release release;
    assets_ = envs::make_assets(config);
    env_ = std::make_shared<envs::BabyBenchEnv>(assets_, seed);
    if (training) env_->attach_log(envs::start_training(*assets_));
    entries_ = [&] {
      py::gil_scoped_acquire acquire;
      return entries_of(env_->observation_space());
    }();
  }
  ~PyEnv() {
    // The log's last record and flush happen at close; never throw from here.
    try {
      close();
    } catch (...) {
    }
  }

  py::tuple reset(std::optional<std::uint64_t> seed) {
    {
      py::gil_scoped_release release;
      env_->reset(seed);
    }
    return py::make_tuple(observation(), info());
  }

  py::tuple step(const Actions& action) {
    const envs::StepResult r = step_without_gil(*env_, action);
    return py::make_tuple(observation(), r.reward, r.terminated, r.truncated, info());
  }

  py::dict observation() {
    py::dict d;
    const envs::ObservationBuffers& obs = env_->observation();
    if (copy_) {
      for (size_t k = 0; k < entries_.size(); ++k) {
        d[entries_[k].key.c_str()] = copy_array(entries_[k], obs.bytes(static_cast<int>(k)));
      }
      return d;
    }
    if (views_.empty()) {
      const py::capsule owner = keep_alive(env_);
      for (size_t k = 0; k < entries_.size(); ++k) {
        views_.push_back(view_array(entries_[k], obs.bytes(static_cast<int>(k)), owner));
      }
    }
    for (size_t k = 0; k < entries_.size(); ++k) d[entries_[k].key.c_str()] = views_[k];
    return d;
  }

  py::dict info() const { return info_dict(env_->info()); }

  // Renders a model camera at width x height (RGB, row 0 at the top).
  py::array render(const IdOrName& camera, int width, int height) {
    const mjModel* m = env_->model();
    const Named cam = named(m, mjOBJ_CAMERA, m->ncam, camera, "camera");
    if (width < 1 || height < 1 || width > 4096 || height > 4096) {
      throw py::value_error("render size must be within 1..4096 pixels");
    }
    if (!renderer_ || width > renderer_width_ || height > renderer_height_) {
      renderer_width_ = std::max(width, renderer_width_);
      renderer_height_ = std::max(height, renderer_height_);
      renderer_.reset();
      renderer_ = std::make_unique<senses::CameraRenderer>(m, renderer_width_, renderer_height_);
    }
    py::array_t<std::uint8_t> image({height, width, 3});
    const std::span<std::uint8_t> out(image.mutable_data(), static_cast<size_t>(image.size()));
    {
      py::gil_scoped_release release;
      renderer_->render(m, env_->render_data(), cam.id, width, height, out);
    }
    return image;
  }

  void close() {
    renderer_.reset();
    if (env_) env_->close();
  }

  envs::BabyBenchEnv& env() { return *env_; }
  const std::shared_ptr<envs::BabyBenchEnv>& shared() const { return env_; }
  const std::shared_ptr<const envs::BabyBenchAssets>& assets() const { return assets_; }
  bool copies() const { return copy_; }

  // Seconds for the C++ loop over `actions` (steps x action dim), resetting at episode ends: the
  // baseline of the Python overhead benchmark.
  double bench(const py::array_t<double, py::array::c_style | py::array::forcecast>& actions) {
    const py::ssize_t dim = env_->action_space().size();
    if (actions.ndim() != 2 || actions.shape(1) != dim) {
      throw py::value_error("actions must have shape (steps, " + std::to_string(dim) + ")");
    }
    const double* a = actions.data();
    const py::ssize_t steps = actions.shape(0);
    py::gil_scoped_release release;
    const auto start = std::chrono::steady_clock::now();
    for (py::ssize_t i = 0; i < steps; ++i) {
      const envs::StepResult r = env_->step({a + i * dim, static_cast<size_t>(dim)});
      if (r.terminated || r.truncated) env_->reset();
    }
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }

 private:
  bool copy_;
  std::shared_ptr<const envs::BabyBenchAssets> assets_;
  std::shared_ptr<envs::BabyBenchEnv> env_;
  std::vector<Entry> entries_;
  std::vector<py::array> views_;  // view mode: one per key, made on first use
  std::unique_ptr<senses::CameraRenderer> renderer_;
  int renderer_width_ = 0, renderer_height_ = 0;
};

py::object model_view(std::shared_ptr<const void> owner, const mjModel* model) {
  return py::cast(ModelView{std::move(owner), model});
}

py::object data_view(std::shared_ptr<const void> owner, const mjModel* model, const mjData* data) {
  return py::cast(DataView{std::move(owner), model, data});
}

void bind_env(py::module_& m) {
  py::class_<Named>(m, "Named", "A named MuJoCo object: its id and name.")
      .def_readonly("id", &Named::id)
      .def_readonly("name", &Named::name)
      .def("__repr__", [](const Named& n) {
        return "<id " + std::to_string(n.id) + ", name '" + n.name + "'>";
      });

  // The reference's env.model is a mujoco.MjModel; this view carries its sizes, named lookups and
  // the arrays users read most.
  py::class_<ModelView>(m, "Model", "Read-only view of the compiled MuJoCo model.")
      .def_property_readonly("nq", [](const ModelView& v) { return v.m()->nq; })
      .def_property_readonly("nv", [](const ModelView& v) { return v.m()->nv; })
      .def_property_readonly("nu", [](const ModelView& v) { return v.m()->nu; })
      .def_property_readonly("na", [](const ModelView& v) { return v.m()->na; })
      .def_property_readonly("nbody", [](const ModelView& v) { return v.m()->nbody; })
      .def_property_readonly("njnt", [](const ModelView& v) { return v.m()->njnt; })
      .def_property_readonly("ngeom", [](const ModelView& v) { return v.m()->ngeom; })
      .def_property_readonly("nsensor", [](const ModelView& v) { return v.m()->nsensor; })
      .def_property_readonly("nsensordata", [](const ModelView& v) { return v.m()->nsensordata; })
      .def_property_readonly("ncam", [](const ModelView& v) { return v.m()->ncam; })
      .def_property_readonly("neq", [](const ModelView& v) { return v.m()->neq; })
      .def_property_readonly("timestep", [](const ModelView& v) { return v.m()->opt.timestep; })
      .def(
          "actuator",
          [](const ModelView& v, const IdOrName& r) {
            return named(v.m(), mjOBJ_ACTUATOR, v.m()->nu, r, "actuator");
          },
          py::arg("key"))
      .def(
          "joint",
          [](const ModelView& v, const IdOrName& r) {
            return named(v.m(), mjOBJ_JOINT, v.m()->njnt, r, "joint");
          },
          py::arg("key"))
      .def(
          "body",
          [](const ModelView& v, const IdOrName& r) {
            return named(v.m(), mjOBJ_BODY, v.m()->nbody, r, "body");
          },
          py::arg("key"))
      .def(
          "geom",
          [](const ModelView& v, const IdOrName& r) {
            return named(v.m(), mjOBJ_GEOM, v.m()->ngeom, r, "geom");
          },
          py::arg("key"))
      .def(
          "sensor",
          [](const ModelView& v, const IdOrName& r) {
            return named(v.m(), mjOBJ_SENSOR, v.m()->nsensor, r, "sensor");
          },
          py::arg("key"))
      .def(
          "camera",
          [](const ModelView& v, const IdOrName& r) {
            return named(v.m(), mjOBJ_CAMERA, v.m()->ncam, r, "camera");
          },
          py::arg("key"))
      .def_property_readonly("actuator_ctrlrange",
                             [](const ModelView& v) {
                               return view_matrix(v.m()->actuator_ctrlrange, v.m()->nu, 2,
                                                  v.owner());
                             })
      .def_property_readonly("actuator_forcerange",
                             [](const ModelView& v) {
                               return view_matrix(v.m()->actuator_forcerange, v.m()->nu, 2,
                                                  v.owner());
                             })
      .def_property_readonly("jnt_range",
                             [](const ModelView& v) {
                               return view_matrix(v.m()->jnt_range, v.m()->njnt, 2, v.owner());
                             })
      .def_property_readonly("qpos0", [](const ModelView& v) {
        return view_matrix(v.m()->qpos0, v.m()->nq, 0, v.owner());
      });

  py::class_<DataView>(m, "Data", "Read-only views of the env's mjData (they follow the env).")
      .def_property_readonly("time", [](const DataView& v) { return v.d()->time; })
      .def_property_readonly("ncon", [](const DataView& v) { return v.d()->ncon; })
      .def_property_readonly(
          "qpos",
          [](const DataView& v) { return view_matrix(v.d()->qpos, v.m()->nq, 0, v.owner()); })
      .def_property_readonly(
          "qvel",
          [](const DataView& v) { return view_matrix(v.d()->qvel, v.m()->nv, 0, v.owner()); })
      .def_property_readonly(
          "qacc",
          [](const DataView& v) { return view_matrix(v.d()->qacc, v.m()->nv, 0, v.owner()); })
      .def_property_readonly(
          "ctrl",
          [](const DataView& v) { return view_matrix(v.d()->ctrl, v.m()->nu, 0, v.owner()); })
      .def_property_readonly(
          "act", [](const DataView& v) { return view_matrix(v.d()->act, v.m()->na, 0, v.owner()); })
      .def_property_readonly("sensordata",
                             [](const DataView& v) {
                               return view_matrix(v.d()->sensordata, v.m()->nsensordata, 0,
                                                  v.owner());
                             })
      .def_property_readonly(
          "xpos",
          [](const DataView& v) { return view_matrix(v.d()->xpos, v.m()->nbody, 3, v.owner()); })
      .def_property_readonly(
          "xmat",
          [](const DataView& v) { return view_matrix(v.d()->xmat, v.m()->nbody, 9, v.owner()); })
      .def_property_readonly("geom_xpos", [](const DataView& v) {
        return view_matrix(v.d()->geom_xpos, v.m()->ngeom, 3, v.owner());
      });

  py::class_<ProprioView>(m, "Proprioception")
      .def_property_readonly(
          "joint_names", [](const ProprioView& v) { return v.env->proprioception().joint_names(); })
      .def_property_readonly(
          "sensor_names",
          [](const ProprioView& v) { return v.env->proprioception().sensor_names(); })
      .def_property_readonly("size",
                             [](const ProprioView& v) { return v.env->proprioception().size(); });

  py::class_<TouchView>(m, "Touch")
      .def_property_readonly("sensor_count",
                             [](const TouchView& v) { return v.touch().sensor_count(); })
      .def_property_readonly("values_per_sensor",
                             [](const TouchView& v) { return v.touch().values_per_sensor(); })
      .def_property_readonly(
          "function",
          [](const TouchView& v) { return std::string(touch_function_name(v.touch().function())); })
      .def_property_readonly(
          "response",
          [](const TouchView& v) { return std::string(touch_response_name(v.touch().response())); })
      .def_property_readonly("bodies", [](const TouchView& v) { return v.touch().bodies(); })
      // MIMo's layout: body id -> (n, 3) sensor positions in the body's frame.
      .def_property_readonly("sensor_positions",
                             [](const TouchView& v) {
                               const senses::Touch& t = v.touch();
                               py::dict out;
                               for (int body : t.bodies()) {
                                 const int n = t.sensors_on_body(body);
                                 py::array_t<double> a({n, 3});
                                 if (n > 0) {
                                   std::memcpy(a.mutable_data(),
                                               t.positions()[t.first_sensor(body)].data(),
                                               sizeof(double) * 3 * n);
                                 }
                                 out[py::int_(body)] = a;
                               }
                               return out;
                             })
      // MIMo's layout of the current touch observation: body id -> (n, values per sensor), as
      // read-only views of the env's buffer.
      .def_property_readonly("sensor_outputs", [](const TouchView& v) {
        const senses::Touch& t = v.touch();
        const int key = v.env->key_index(envs::BabyBenchEnv::kTouchKey);
        const std::span<const float> obs = v.env->observation().f32(key);
        const py::capsule owner = keep_alive(v.env);
        const int per = t.values_per_sensor();
        py::dict out;
        for (int body : t.bodies()) {
          const int n = t.sensors_on_body(body);
          const float* data =
              n > 0 ? obs.data() + static_cast<size_t>(t.first_sensor(body)) * per : obs.data();
          py::array a(py::dtype::of<float>(), {n, per}, {}, data, owner);
          py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
          out[py::int_(body)] = a;
        }
        return out;
      });

  py::class_<PyEnv>(m, "Env", "One BabyBench env stepped in C++ (use cradle.make_env).")
      .def(py::init<const Config&, bool, std::uint64_t, bool>(), py::arg("config"),
           py::arg("training"), py::arg("seed") = 0, py::arg("copy") = true)
      .def("reset", &PyEnv::reset, py::arg("seed") = py::none())
      .def("step", &PyEnv::step, py::arg("action"))
      .def("observation", &PyEnv::observation)
      .def("info", &PyEnv::info)
      .def("render", &PyEnv::render, py::arg("camera"), py::arg("width"), py::arg("height"))
      .def("close", &PyEnv::close)
      .def("bench", &PyEnv::bench, py::arg("actions"))
      .def_property_readonly("copies", &PyEnv::copies)
      // Wall seconds spent inside the C++ env's steps since the last clear_profile(): the rest of
      // a loop's time is the loop's own overhead (Python or C++).
      .def_property_readonly("profile_seconds",
                             [](PyEnv& e) {
                               const envs::Profile& p = e.env().profile();
                               return p.physics + p.touch + p.vision + p.proprio + p.vestibular +
                                      p.other;
                             })
      .def("clear_profile", [](PyEnv& e) { e.env().clear_profile(); })
      .def_property_readonly("observation_space",
                             [](PyEnv& e) { return space_list(e.env().observation_space()); })
      .def_property_readonly("action_space",
                             [](PyEnv& e) { return box_tuple(e.env().action_space()); })
      .def_property_readonly("config", [](PyEnv& e) { return e.env().config(); })
      .def_property_readonly("episode_steps", [](PyEnv& e) { return e.env().episode_steps(); })
      .def_property_readonly(
          "dt",
          [](PyEnv& e) { return e.env().config().frame_skip * e.env().model()->opt.timestep; })
      .def_property_readonly("model",
                             [](PyEnv& e) {
                               return ModelView{e.assets(), e.assets()->model.get()};
                             })
      .def_property_readonly("data",
                             [](PyEnv& e) {
                               return DataView{e.shared(), e.env().model(), e.env().data()};
                             })
      .def_property_readonly("proprioception", [](PyEnv& e) { return ProprioView{e.shared()}; })
      .def_property_readonly("touch", [](PyEnv& e) -> py::object {
        if (!e.env().touch()) return py::none();
        return py::cast(TouchView{e.shared()});
      });
}

}  // namespace cradle::python

// Every env of the registry (envs/registry.h) for Python: `_cradle.env_specs`, `env_spec` and
// `RegistryEnv`, one env of any id behind the envs::Env interface, for python/cradle/registry.py.
// Observations are fresh numpy arrays with the space's dtypes; what only some families have
// (MuJoCo model and data views, a renderer, a task read-back) is found by a dynamic_cast.
#include "envs/registry.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "envs/babybench.h"
#include "envs/mimo/sample_env.h"
#include "envs/sami/sami_env.h"
#include "envs/tma/tma_env.h"
#include "python/common.h"
#include "sami/env.h"
#include "sami/render.h"
#include "tma/render.h"

namespace cradle::python {
namespace {

// Raises NotImplementedError with `message`.
[[noreturn]] void not_implemented(const std::string& message) {
  PyErr_SetString(PyExc_NotImplementedError, message.c_str());
  throw py::error_already_set();
}

class PyRegistryEnv {
 public:
  // index: the env's place in a vector (SaMI: its training set), -1 for a lone env.
  PyRegistryEnv(const std::string& id, std::uint64_t seed, const envs::EnvOptions& options,
                int index)
      : spec_(envs::env_spec(id)) {
    if (index < -1) throw UserError("vector index must be -1 (a lone env) or more");
    {
      py::gil_scoped_release release;
      env_ = envs::env_maker(id, options)(index, seed);
    }
    entries_ = entries_of(env_->observation_space());
    mimo_ = dynamic_cast<envs::MimoEnv*>(env_.get());
    tma_ = dynamic_cast<envs::TmaEnvAdapter*>(env_.get());
    sami_ = dynamic_cast<envs::SamiEnvAdapter*>(env_.get());
    babybench_ = dynamic_cast<envs::BabyBenchEnv*>(env_.get());
  }
  ~PyRegistryEnv() {
    try {
      close();
    } catch (...) {
    }
  }

  const envs::EnvSpec& spec() const { return spec_; }
  envs::Env& env() { return *env_; }

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

  py::dict observation() const {
    py::dict d;
    const envs::ObservationBuffers& obs = env_->observation();
    for (size_t k = 0; k < entries_.size(); ++k) {
      d[entries_[k].key.c_str()] = copy_array(entries_[k], obs.bytes(static_cast<int>(k)));
    }
    return d;
  }

  // The env's info; a SaMI env's also holds the hidden parameters and labels, as cradle.sami's.
  py::dict info() const {
    py::dict d = info_dict(env_->info());
    if (sami_) {
      for (const auto& [key, value] : sami_info(sami_->sami())) {
        if (!d.contains(key)) d[key] = value;
      }
    }
    return d;
  }

  void set_reset_options(const envs::ResetOptions& options) { env_->set_reset_options(options); }

  py::object score() const {
    const double s = env_->score();
    return std::isnan(s) ? py::none() : py::cast(s);
  }

  bool renders() const { return mimo_ || tma_ || sami_; }

  // An RGB frame (height, width, 3); 0 x 0 takes the family's default size.
  py::array render(int width, int height) {
    if (!renders()) {
      not_implemented("env '" + spec_.id + "' has no renderer here (BabyBench renders through " +
                      "cradle.make('" + spec_.id + "'), a BabyBenchEnv)");
    }
    if (width == 0 && height == 0) {
      if (mimo_) width = height = mimo_->render_size();
      if (tma_) width = 600, height = 400;
      if (sami_) width = 320, height = 240;
    }
    if (width < 16 || height < 16 || width > 4096 || height > 4096) {
      throw UserError("render size " + std::to_string(width) + " x " + std::to_string(height) +
                      " is out of range (expected 16 to 4096 pixels each)");
    }
    if (mimo_ && (width != mimo_->render_size() || height != mimo_->render_size())) {
      throw UserError("MIMo sample envs render at their render size, " +
                      std::to_string(mimo_->render_size()) + " x " +
                      std::to_string(mimo_->render_size()));
    }
    py::array_t<std::uint8_t> out({height, width, 3});
    const std::span<std::uint8_t> rgb(out.mutable_data(), static_cast<size_t>(out.size()));
    {
      py::gil_scoped_release release;
      if (mimo_) {
        mimo_->render(rgb);
      } else if (tma_) {
        std::vector<std::uint8_t> frame;
        tma::render(tma_->env(), width, height, /*draw_lidars=*/true, frame);
        std::copy(frame.begin(), frame.end(), rgb.begin());
      } else {
        if (!sami_renderer_ || sami_renderer_->width() != width ||
            sami_renderer_->height() != height) {
          sami_renderer_.reset();
          sami_renderer_ = std::make_unique<sami::Renderer>(sami_->sami(), width, height);
        }
        sami_renderer_->render(sami_->sami(), rgb);
      }
    }
    return out;
  }

  // Read-only views of the MuJoCo model and data (None for Box2D's TeachMyAgent).
  py::object model() const {
    if (sami_) return sami_model_view(sami_env());
    if (mimo_) return model_view(env_, mimo_->model());
    if (babybench_) return model_view(env_, babybench_->model());
    return py::none();
  }
  py::object data() const {
    if (sami_) return sami_data_view(sami_env());
    if (mimo_) return data_view(env_, mimo_->model(), mimo_->data());
    if (babybench_) return data_view(env_, babybench_->model(), babybench_->data());
    return py::none();
  }

  // The current episode's task, named as the reset options: TeachMyAgent's terrain parameters,
  // SaMI's hidden parameters. None for the families that do not read theirs back.
  py::object task() const {
    py::dict d;
    if (tma_) {
      const tma::TmaEnv& e = tma_->env();
      if (e.options().env == tma::EnvId::kStumpTracks) {
        const tma::StumpTask& t = e.stump_task();
        d["stump_height"] = t.stump_height;
        d["obstacle_spacing"] = t.obstacle_spacing;
        d["roughness"] = t.roughness;
        if (t.stump_width) {
          d["stump_width_0"] = (*t.stump_width)[0];
          d["stump_width_1"] = (*t.stump_width)[1];
        }
        if (t.stump_rot) {
          d["stump_rot_0"] = (*t.stump_rot)[0];
          d["stump_rot_1"] = (*t.stump_rot)[1];
        }
      } else {
        const tma::ParkourTask& t = e.parkour_task();
        for (size_t i = 0; i < t.input_vector.size(); ++i) {
          d[("input_vector_" + std::to_string(i)).c_str()] = t.input_vector[i];
        }
        d["water_level"] = t.water_level;
        if (t.creepers_width) d["creepers_width"] = *t.creepers_width;
        if (t.creepers_height) d["creepers_height"] = *t.creepers_height;
        d["creepers_spacing"] = t.creepers_spacing;
        d["terrain_cppn_scale"] = t.terrain_cppn_scale;
      }
      return d;
    }
    if (sami_) {
      const sami::SamiEnv& e = sami_->sami();
      const sami::Info& i = e.info();
      if (e.spec().id == sami::EnvId::kPandaPush) {
        d["table_friction"] = i.friction;
        d["cube_mass"] = i.mass;
      } else {
        d["mass"] = i.mass;
        d["damping"] = i.damping;
      }
      return d;
    }
    return py::none();
  }

  void close() {
    sami_renderer_.reset();
    if (env_) env_->close();
  }

 private:
  // The SaMI env inside the adapter, sharing the adapter's ownership.
  std::shared_ptr<sami::SamiEnv> sami_env() const {
    return std::shared_ptr<sami::SamiEnv>(env_, &sami_->sami());
  }

  envs::EnvSpec spec_;
  std::shared_ptr<envs::Env> env_;
  std::vector<Entry> entries_;
  envs::MimoEnv* mimo_ = nullptr;
  envs::TmaEnvAdapter* tma_ = nullptr;
  envs::SamiEnvAdapter* sami_ = nullptr;
  envs::BabyBenchEnv* babybench_ = nullptr;
  std::unique_ptr<sami::Renderer> sami_renderer_;
};

}  // namespace

void bind_registry(py::module_& m) {
  py::class_<envs::EnvSpec>(m, "EnvSpec", "A listed env id: its family, limits and task space.")
      .def_readonly("id", &envs::EnvSpec::id)
      .def_readonly("family", &envs::EnvSpec::family)
      .def_readonly("summary", &envs::EnvSpec::summary)
      .def_readonly("max_episode_steps", &envs::EnvSpec::max_episode_steps)
      .def_readonly("aliases", &envs::EnvSpec::aliases)
      .def_readonly("natural_envs", &envs::EnvSpec::natural_envs)
      .def_readonly("config", &envs::EnvSpec::config)
      .def_property_readonly("task_parameters",
                             [](const envs::EnvSpec& s) {
                               py::dict d;
                               for (const envs::TaskParameter& p : s.parameters) {
                                 d[p.name.c_str()] = py::make_tuple(p.low, p.high);
                               }
                               return d;
                             })
      .def("__repr__", [](const envs::EnvSpec& s) {
        return "<EnvSpec " + s.id + " family=" + s.family +
               " max_episode_steps=" + std::to_string(s.max_episode_steps) + ">";
      });
  m.def("env_specs", &envs::env_specs, "Every listed env id, by family then name.");
  m.def("env_spec", &envs::env_spec, py::arg("id"),
        "The spec of an id, an alias or a YAML path; ValueError naming the closest ids.");
  m.def("close_env_ids", &envs::close_env_ids, py::arg("id"), py::arg("count") = 3,
        "The listed ids closest to `id`, best first.");

  py::class_<PyRegistryEnv>(m, "RegistryEnv", "One env of any registry id (use cradle.make).")
      .def(py::init<const std::string&, std::uint64_t, const envs::EnvOptions&, int>(),
           py::arg("id"), py::arg("seed") = 0, py::arg("options") = envs::EnvOptions{},
           py::arg("index") = -1)
      .def_property_readonly("spec", &PyRegistryEnv::spec)
      .def_property_readonly(
          "observation_space",
          [](PyRegistryEnv& e) { return space_list(e.env().observation_space()); })
      .def_property_readonly("action_space",
                             [](PyRegistryEnv& e) { return box_tuple(e.env().action_space()); })
      .def("reset", &PyRegistryEnv::reset, py::arg("seed") = py::none())
      .def("step", &PyRegistryEnv::step, py::arg("action"))
      .def("observation", &PyRegistryEnv::observation)
      .def("info", &PyRegistryEnv::info)
      .def("set_reset_options", &PyRegistryEnv::set_reset_options, py::arg("options"))
      .def("score", &PyRegistryEnv::score)
      .def_property_readonly("renders", &PyRegistryEnv::renders)
      .def("render", &PyRegistryEnv::render, py::arg("width") = 0, py::arg("height") = 0)
      .def_property_readonly("model", &PyRegistryEnv::model)
      .def_property_readonly("data", &PyRegistryEnv::data)
      .def("task", &PyRegistryEnv::task)
      .def("close", &PyRegistryEnv::close);
}

}  // namespace cradle::python

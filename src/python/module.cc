// `_cradle`: the extension module behind the Python package `cradle` (python/cradle/). It holds
// only what must be C++ (envs, vector envs, learners, evaluation); the Gymnasium-shaped classes
// around it are plain Python.
#include <pybind11/operators.h>

#include <cstring>
#include <string_view>

#include "core/error.h"
#include "python/common.h"

namespace cradle::python {

std::vector<Entry> entries_of(const DictSpace& space) {
  std::vector<Entry> out;
  for (const auto& [key, box] : space.entries) {
    Entry e{.key = key, .dtype = py::dtype(std::string(dtype_name(box.dtype)))};
    for (int d : box.shape) e.shape.push_back(d);
    e.bytes = static_cast<size_t>(box.size()) * dtype_size(box.dtype);
    out.push_back(std::move(e));
  }
  return out;
}

py::array copy_array(const Entry& entry, std::span<const std::byte> data) {
  py::array out(entry.dtype, entry.shape);
  std::memcpy(out.mutable_data(), data.data(), entry.bytes);
  return out;
}

namespace {

// Clears numpy's WRITEABLE flag: views of C++ buffers must not be written from Python.
void make_read_only(py::array& a) {
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
}

}  // namespace

py::array view_array(const Entry& entry, std::span<const std::byte> data, py::handle owner) {
  py::array out(entry.dtype, entry.shape, {}, data.data(), owner);
  make_read_only(out);
  return out;
}

py::array view_doubles(const double* data, py::ssize_t n, py::handle owner) {
  py::array out(py::dtype::of<double>(), {n}, {}, data, owner);
  make_read_only(out);
  return out;
}

py::object info_value(const envs::Info& info, int slot) {
  switch (info.type(slot)) {
    case envs::InfoType::kBool:
      return py::bool_(info.flag(slot));
    case envs::InfoType::kInt:
      return py::int_(static_cast<long>(info.number(slot)));
    case envs::InfoType::kReal:
      return py::float_(info.number(slot));
    case envs::InfoType::kIntList:
      break;
  }
  const std::span<const int> list = info.list(slot);
  return py::cast(std::vector<int>(list.begin(), list.end()));
}

py::dict info_dict(const envs::Info& info) {
  py::dict d;
  for (int k = 0; k < info.size(); ++k) {
    if (info.published(k)) d[info.name(k).c_str()] = info_value(info, k);
  }
  d["steps"] = info.steps;
  return d;
}

envs::StepResult step_without_gil(envs::Env& env, const Actions& action) {
  const py::ssize_t n = env.action_space().size();
  if (action.size() != n) {
    throw py::value_error("action has " + std::to_string(action.size()) + " values, expected " +
                          std::to_string(n));
  }
  const std::span<const double> a(action.data(), static_cast<size_t>(n));
  return without_gil([&] { return env.step(a); });
}

py::tuple box_tuple(const Box& box) {
  py::tuple shape(box.shape.size());
  for (size_t i = 0; i < box.shape.size(); ++i) shape[i] = box.shape[i];
  return py::make_tuple(shape, std::string(dtype_name(box.dtype)), py::array(py::cast(box.low)),
                        py::array(py::cast(box.high)));
}

py::list space_list(const DictSpace& space) {
  py::list out;
  for (const auto& [key, box] : space.entries) {
    py::tuple b = box_tuple(box);
    out.append(py::make_tuple(key, b[0], b[1], b[2], b[3]));
  }
  return out;
}

Config config_from_text(const std::string& text, const std::string& source) {
  return parse_config(text, source);
}

}  // namespace cradle::python

namespace py = pybind11;
using cradle::Config;

PYBIND11_MODULE(_cradle, m) {
  m.doc() =
      "Cradle's C++ core (envs, vector envs, learners, evaluation); use the `cradle` package.";
  m.attr("__version__") = CRADLE_VERSION;

  // User errors become ValueError with the one-line message; a missing file FileNotFoundError.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const cradle::UserError& e) {
      const std::string_view what = e.what();
      if (what.find("no such file") != std::string_view::npos ||
          what.find("does not exist") != std::string_view::npos) {
        PyErr_SetString(PyExc_FileNotFoundError, e.what());
      } else {
        PyErr_SetString(PyExc_ValueError, e.what());
      }
    } catch (const py::error_already_set&) {
      throw;  // a Python exception: as it is
    } catch (const py::builtin_exception&) {
      throw;  // pybind's own (value_error, ...): its translator
    } catch (const std::exception& e) {
      // Anything else: one line, never an empty message.
      std::string message = e.what();
      for (char& ch : message) ch = (ch == '\n' || ch == '\r') ? ' ' : ch;
      if (message.empty()) message = "internal error (no message)";
      PyErr_SetString(PyExc_RuntimeError, ("cradle: internal error: " + message).c_str());
    }
  });

  py::class_<Config>(m, "Config", "A parsed BabyBench config (see cradle.make_env).")
      .def_readonly("save_dir", &Config::save_dir)
      .def_readonly("max_episode_steps", &Config::max_episode_steps)
      .def_readonly("frame_skip", &Config::frame_skip)
      .def_readonly("render_size", &Config::render_size)
      .def_property_readonly(
          "behavior",
          [](const Config& c) { return std::string(cradle::behavior_name(c.behavior)); })
      .def("to_yaml", [](const Config& c) { return cradle::to_yaml(c); })
      .def("to_json", [](const Config& c) { return cradle::to_json(c).dump(); })
      .def(py::self == py::self);
  m.def("parse_config", &cradle::python::config_from_text, py::arg("text"), py::arg("source"),
        "Parses YAML (or JSON) config text; `source` names it in error messages.");
  m.def(
      "load_config", [](const std::string& path) { return cradle::load_config(path); },
      py::arg("path"), "Reads and parses a YAML config file.");
  m.def("default_config", &cradle::default_config);
  m.def("config_keys", [] {
    const auto keys = cradle::config_keys();
    return std::vector<std::string>(keys.begin(), keys.end());
  });

  cradle::python::bind_env(m);
  cradle::python::bind_learn(m);
  cradle::python::bind_tma(m);
  cradle::python::bind_sami(m);
  cradle::python::bind_teach(m);
  cradle::python::bind_registry(m);
  cradle::python::bind_run_policy(m);
}

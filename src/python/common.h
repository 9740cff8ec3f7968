// Shared pieces of the `_cradle` extension module: numpy conversion of observation buffers and
// spaces, info dicts, and the registration functions of each binding file.
#pragma once

#include <mujoco/mujoco.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstddef>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/config.h"
#include "core/spaces.h"
#include "envs/env.h"

namespace cradle::sami {
class SamiEnv;
}  // namespace cradle::sami

namespace cradle::python {

namespace py = pybind11;

// What is needed to turn one observation entry into a numpy array without looking up its Box.
struct Entry {
  std::string key;
  py::dtype dtype;
  std::vector<py::ssize_t> shape;
  size_t bytes = 0;
};
std::vector<Entry> entries_of(const DictSpace& space);

// A fresh array holding a copy of `data`.
py::array copy_array(const Entry& entry, std::span<const std::byte> data);
// A read-only array over `data` (no copy) that keeps `owner` alive.
py::array view_array(const Entry& entry, std::span<const std::byte> data, py::handle owner);
// A read-only 1-D float64 array over `n` values that keeps `owner` alive.
py::array view_doubles(const double* data, py::ssize_t n, py::handle owner);

// The reference's info dict of a behaviour (Cradle's extra hand-regard keys included).
// The info's published keys (in declaration order) and "steps"; info_value: one key's value.
py::object info_value(const envs::Info& info, int slot);
py::dict info_dict(const envs::Info& info);

// A space as Python data: [(key, shape tuple, dtype name, low array, high array), ...].
py::tuple box_tuple(const Box& box);
py::list space_list(const DictSpace& space);

// Runs `work` with the GIL released (C++ that trains, evaluates or builds envs and touches no
// Python object) and returns its result.
template <typename Work>
auto without_gil(Work&& work) {
  py::gil_scoped_release release;
  return work();
}

// Actions as Python passes them (any sequence of numbers, converted to contiguous doubles).
using Actions = py::array_t<double, py::array::c_style | py::array::forcecast>;
// Checks the action's size (ValueError) and steps the env with the GIL released.
envs::StepResult step_without_gil(envs::Env& env, const Actions& action);

// Parses a config from YAML text (dicts arrive as JSON, a YAML subset); UserError -> ValueError.
Config config_from_text(const std::string& text, const std::string& source);

// Read-only views of a compiled MuJoCo model and of an env's mjData (env.cc's `Model` and `Data`
// classes), for any env that has them; `owner` keeps the memory alive while a view or an array
// taken from it lives.
py::object model_view(std::shared_ptr<const void> owner, const mjModel* model);
py::object data_view(std::shared_ptr<const void> owner, const mjModel* model, const mjData* data);
// A SaMI env's views (sami.cc's `SamiModel` and `SamiData`: this episode's hidden parameters
// included) and its info dict (steps, the task set, the hidden parameters and labels).
py::object sami_model_view(std::shared_ptr<sami::SamiEnv> env);
py::object sami_data_view(std::shared_ptr<sami::SamiEnv> env);
py::dict sami_info(const sami::SamiEnv& env);

void bind_env(py::module_& m);
void bind_learn(py::module_& m);
void bind_tma(py::module_& m);
void bind_sami(py::module_& m);
void bind_teach(py::module_& m);
void bind_registry(py::module_& m);    // registry.cc, after bind_env and bind_sami (their views)
void bind_sami_learn(py::module_& m);  // sami_learn.cc, called by bind_sami
void bind_tma_run(py::module_& m);     // tma_run.cc, called by bind_tma
void bind_run_policy(py::module_& m);  // run_policy.cc: a run's trained policy, by its folder

}  // namespace cradle::python

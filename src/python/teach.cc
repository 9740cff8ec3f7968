// `_cradle.Teacher` and `_cradle.make_teacher`: the curriculum teachers of src/teach/ for Python;
// cradle/teach.py gives them numpy-friendly signatures. Kwargs and book-keeping cross as JSON text.
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "python/common.h"
#include "teach/registry.h"

namespace cradle::python {
namespace {

using teach::DiagGaussian;
using teach::Task;
using teach::Teacher;

// (mean, variance) pairs from Python; None stays empty.
std::optional<DiagGaussian> dist_of(const std::optional<std::pair<Task, Task>>& d) {
  if (!d) return std::nullopt;
  return DiagGaussian{d->first, d->second};
}

py::array_t<float> array_of(const Task& t) {
  py::array_t<float> a(static_cast<py::ssize_t>(t.size()));
  for (std::size_t i = 0; i < t.size(); ++i) a.mutable_at(static_cast<py::ssize_t>(i)) = t[i];
  return a;
}

}  // namespace

void bind_teach(py::module_& m) {
  m.def("teacher_names", [] { return teach::teacher_names(); });
  py::class_<Teacher>(m, "Teacher", "A curriculum teacher (see cradle.teach.make_teacher).")
      .def_property_readonly("name", &Teacher::name)
      .def_property_readonly("dims", &Teacher::dims)
      .def("sample_task", [](Teacher& t) { return array_of(t.sample_task()); })
      .def("non_exploratory_task_sampling",
           [](Teacher& t) { return array_of(t.non_exploratory_task_sampling()); })
      .def("is_non_exploratory_task_sampling_available",
           &Teacher::is_non_exploratory_task_sampling_available)
      .def("record_initial_state", &Teacher::record_initial_state, py::arg("task"), py::arg("s0"))
      .def("step_update", &Teacher::step_update, py::arg("s"), py::arg("a"), py::arg("r"),
           py::arg("s_next"), py::arg("done"))
      .def("episodic_update", &Teacher::episodic_update, py::arg("task"), py::arg("ret"),
           py::arg("success"))
      .def(
          "set_value_estimator",
          [](Teacher& t, py::object fn) {
            if (fn.is_none()) return t.set_value_estimator(nullptr);
            if (!PyCallable_Check(fn.ptr()))
              throw UserError("set_value_estimator: expected a callable (states -> values)");
            // States reach the function as an (n, state_dim) float32 array.
            t.set_value_estimator([fn](const std::vector<std::vector<float>>& states) {
              const py::ssize_t n = static_cast<py::ssize_t>(states.size());
              const py::ssize_t d = n ? static_cast<py::ssize_t>(states[0].size()) : 0;
              py::array_t<float> a({n, d});
              for (py::ssize_t i = 0; i < n; ++i) {
                if (static_cast<py::ssize_t>(states[i].size()) != d)
                  throw UserError("value estimator: initial states of different sizes");
                for (py::ssize_t j = 0; j < d; ++j) a.mutable_at(i, j) = states[i][j];
              }
              py::array_t<float, py::array::c_style | py::array::forcecast> v(fn(a));
              return std::vector<float>(v.data(), v.data() + v.size());
            });
          },
          py::arg("fn"))
      .def("dump_json", [](const Teacher& t) { return t.dump().dump(); });
  m.def(
      "make_teacher",
      [](const std::string& name, const Task& mins, const Task& maxs, std::uint64_t seed,
         const std::string& expert_knowledge, const std::string& params_json,
         const std::optional<std::pair<Task, Task>>& initial_dist,
         const std::optional<std::pair<Task, Task>>& target_dist, double reward_lb,
         double reward_ub, bool scale_reward) {
        teach::TeacherSetup s{.name = name, .mins = mins, .maxs = maxs, .seed = seed};
        s.expert_knowledge = teach::parse_expert_knowledge(expert_knowledge);
        s.initial_dist = dist_of(initial_dist);
        s.target_dist = dist_of(target_dist);
        s.reward_lb = reward_lb;
        s.reward_ub = reward_ub;
        s.scale_reward = scale_reward;
        s.params = nlohmann::json::parse(params_json, nullptr, /*allow_exceptions=*/false);
        if (s.params.is_discarded()) throw UserError("make_teacher: params are not valid JSON");
        return teach::make_teacher(s);
      },
      py::arg("name"), py::arg("mins"), py::arg("maxs"), py::arg("seed"),
      py::arg("expert_knowledge"), py::arg("params_json"), py::arg("initial_dist"),
      py::arg("target_dist"), py::arg("reward_lb"), py::arg("reward_ub"), py::arg("scale_reward"));
}

}  // namespace cradle::python

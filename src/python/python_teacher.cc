#include "python/python_teacher.h"

#include <cmath>
#include <mutex>
#include <optional>
#include <sstream>
#include <utility>
#include <vector>

#include "core/error.h"

namespace cradle::python {

struct PythonTeacher::State {
  py::object object;
  std::string name;  // the object's class name (messages, dumps)
  bool has_dump = false, has_non_exploratory = false;
  std::mutex mutex;
  std::optional<py::error_already_set> error;  // the first exception a call raised
  std::string message;                         // and its PythonTeacherError's message
};

namespace {

std::string text(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

// A Python value's repr on one short line, for messages.
std::string short_repr(const py::handle value) {
  std::string r = py::repr(value).cast<std::string>();
  for (char& c : r) c = (c == '\n' || c == '\r') ? ' ' : c;
  return r.size() > 80 ? r.substr(0, 77) + "..." : r;
}

bool has_method(const py::handle object, const char* name) {
  return py::hasattr(object, name) && PyCallable_Check(object.attr(name).ptr()) != 0;
}

// The run's side of a Python teacher. Every method that reaches Python takes the GIL itself: the
// run calls them from the thread that resets an env (a vector's worker or the training thread,
// which holds no GIL), always with the controller's mutex held, never the other way round.
class Adapter final : public teach::Teacher {
 public:
  Adapter(std::shared_ptr<PythonTeacher::State> state, const teach::TaskSpace& space,
          std::uint64_t seed)
      : Teacher(space.mins(), space.maxs(), seed),
        state_(std::move(state)),
        names_(space.dim_names()) {}

  teach::Task sample_task() override { return task_from("sample_task"); }

  // Without the method, snapshots would spend the teacher's own samples: none are taken.
  teach::Task non_exploratory_task_sampling() override {
    return state_->has_non_exploratory ? task_from("non_exploratory_task_sampling") : sample_task();
  }
  bool is_non_exploratory_task_sampling_available() const override {
    return state_->has_non_exploratory;
  }

  void episodic_update(const teach::Task& task, double ret, bool success) override {
    check_episode(task, ret);
    py::gil_scoped_acquire gil;
    py::array_t<float> values(static_cast<py::ssize_t>(task.size()));
    for (std::size_t i = 0; i < task.size(); ++i)
      values.mutable_at(static_cast<py::ssize_t>(i)) = task[i];
    call("episodic_update",
         [&] { return state_->object.attr("episodic_update")(values, ret, success); });
  }

  // Cradle's keys (teacher, mins, maxs), then the object's dump() dict, written as json.dumps
  // writes it (the object's keys never replace Cradle's).
  nlohmann::json dump() const override {
    nlohmann::json out = Teacher::dump();
    if (!state_->has_dump) return out;
    py::gil_scoped_acquire gil;
    const py::object d = call("dump", [&] { return state_->object.attr("dump")(); });
    const std::string what = "teacher " + state_->name + ": dump() returned ";
    if (!py::isinstance<py::dict>(d))
      throw UserError(what + short_repr(d) + "; expected a dict of JSON values");
    std::string json_text;
    try {
      json_text = py::module_::import("json")
                      .attr("dumps")(d, py::arg("allow_nan") = false)
                      .cast<std::string>();
    } catch (const py::error_already_set& e) {
      throw UserError(what + "a dict that is not JSON (" + py::str(e.value()).cast<std::string>() +
                      "); expected JSON values");
    }
    const nlohmann::json own = nlohmann::json::parse(json_text);
    for (const auto& [key, value] : own.items())
      if (!out.contains(key)) out[key] = value;
    return out;
  }

  const char* name() const override { return state_->name.c_str(); }

 private:
  // Runs one call into Python (GIL held); its exception waits in the state for the binding and a
  // one-line PythonTeacherError naming it stops the run.
  template <typename Call>
  py::object call(const char* method, Call&& fn) const {
    try {
      return fn();
    } catch (py::error_already_set& e) {
      std::string message = "teacher " + state_->name + "." + method + "() raised " +
                            py::str(e.type().attr("__name__")).cast<std::string>() + ": " +
                            py::str(e.value()).cast<std::string>();
      for (char& c : message) c = (c == '\n' || c == '\r') ? ' ' : c;
      {
        std::lock_guard lock(state_->mutex);
        if (!state_->error) {
          state_->error = e;
          state_->message = message;
        }
      }
      throw PythonTeacherError(message);
    }
  }

  // The method's task: a 1-D sequence of finite numbers, one per dimension, inside the bounds.
  teach::Task task_from(const char* method) {
    py::gil_scoped_acquire gil;
    const py::object r = call(method, [&] { return state_->object.attr(method)(); });
    const std::string what = "teacher " + state_->name + ": " + method + "() returned ";
    std::string dims;
    for (const std::string& n : names_) dims += (dims.empty() ? "" : ", ") + n;
    const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(r);
    if (!a || a.ndim() != 1 || a.size() != dims_count()) {
      throw UserError(what + short_repr(r) + "; expected a sequence of " +
                      std::to_string(dims_count()) + " numbers (" + dims + ")");
    }
    teach::Task task(a.size());
    for (py::ssize_t i = 0; i < a.size(); ++i) {
      const double v = a.at(i);
      const std::string bounds = "[" + text(mins_[i]) + ", " + text(maxs_[i]) + "]";
      if (!std::isfinite(v))
        throw UserError(what + names_[i] + " = " + text(v) + "; expected a number in " + bounds);
      task[i] = static_cast<float>(v);
      if (task[i] < mins_[i] || task[i] > maxs_[i]) {
        throw UserError(what + names_[i] + " = " + text(v) + ", outside its bounds " + bounds +
                        " (the task space's)");
      }
    }
    return task;
  }

  py::ssize_t dims_count() const { return static_cast<py::ssize_t>(names_.size()); }

  std::shared_ptr<PythonTeacher::State> state_;
  std::vector<std::string> names_;
};

}  // namespace

PythonTeacher::PythonTeacher(py::object teacher)
    // Released wherever the last holder lets go (the run may end on any thread): with the GIL.
    : state_(new State, [](State* s) {
        py::gil_scoped_acquire gil;
        delete s;
      }) {
  state_->name = py::str(py::type::handle_of(teacher).attr("__name__")).cast<std::string>();
  const char* const protocol =
      "; a teacher is a name (str) or an object with sample_task() -> task and "
      "episodic_update(task, episode_return, success) (docs/curricula.md)";
  if (!has_method(teacher, "sample_task"))
    throw UserError("teacher " + short_repr(teacher) + " has no method sample_task()" + protocol);
  if (!has_method(teacher, "episodic_update")) {
    throw UserError("teacher " + short_repr(teacher) +
                    " has no method episodic_update(task, episode_return, success)" + protocol);
  }
  state_->has_dump = has_method(teacher, "dump");
  state_->has_non_exploratory = has_method(teacher, "non_exploratory_task_sampling");
  state_->object = std::move(teacher);
}

train::TeacherFactory PythonTeacher::factory() const {
  return [state = state_](const teach::TaskSpace& space, std::uint64_t seed) {
    return std::make_unique<Adapter>(state, space, seed);
  };
}

void PythonTeacher::raise_if_failed() const {
  // The first failed call's (envs failing at once may surface another's PythonTeacherError).
  std::optional<py::error_already_set> e;
  std::string message;
  {
    std::lock_guard lock(state_->mutex);
    e = std::exchange(state_->error, std::nullopt);
    message = state_->message;
  }
  if (!e) return;
  // Ctrl-C (and exit()) inside the teacher stop the run as they would anywhere else.
  if (!e->matches(PyExc_Exception)) {
    e->restore();
    throw py::error_already_set();
  }
  py::raise_from(*e, PyExc_RuntimeError, message.c_str());
  throw py::error_already_set();
}

}  // namespace cradle::python

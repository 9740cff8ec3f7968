// A curriculum teacher written in Python for a C++ run (cradle.train(teacher=obj)): any object
// with sample_task() and episodic_update(task, episode_return, success), optionally dump() and
// non_exploratory_task_sampling() (docs/curricula.md). The run calls it from whatever thread
// resets an env (a vector's worker threads included), taking the GIL for each call.
#pragma once

#include <memory>
#include <stdexcept>
#include <string>

#include "python/common.h"
#include "train/task_space.h"

namespace cradle::python {

// A Python teacher's method raised: its message, while the exception itself waits in the
// teacher's PythonTeacher for the binding to raise it.
class PythonTeacherError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

class PythonTeacher {
 public:
  // Checks the protocol with the GIL held: UserError naming the first missing method.
  explicit PythonTeacher(py::object teacher);

  // Makes the run's teacher: every one made shares this object and its error slot.
  train::TeacherFactory factory() const;
  // With the GIL held, after the run threw a PythonTeacherError: raises (as error_already_set) a
  // RuntimeError with the first failed call's message whose __cause__ is the teacher's own
  // exception; a KeyboardInterrupt or SystemExit is raised as it is. Does nothing when no teacher
  // call raised.
  void raise_if_failed() const;

  struct State;  // the object, what it has, the first exception of its calls

 private:
  std::shared_ptr<State> state_;
};

}  // namespace cradle::python

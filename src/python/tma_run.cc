// cradle.tma.run: `cradle tma run` (train/tma_student.h) from Python, with the same checks and run
// folder. The GIL is released while C++ trains.
#include <string>

#include "python/common.h"
#include "train/tma_student.h"

namespace cradle::python {

void bind_tma_run(py::module_& m) {
  m.def(
      "tma_run",
      [](const train::TmaRunArguments& a) {
        const train::TmaRun run = without_gil([&] { return train::run_tma(a); });
        // summary.json's figures (null: none, e.g. PPO's gradient steps) and the run folder.
        py::dict d = py::module_::import("json").attr("loads")(run.summary.dump());
        d["run"] = run.out.string();
        return d;
      },
      py::arg("arguments"));
  // The arguments as keyword fields (python/cradle/tma.py fills them from run()'s keywords).
  py::class_<train::TmaRunArguments>(m, "TmaRunArguments")
      .def(py::init<>())
      .def_readwrite("exp_name", &train::TmaRunArguments::exp_name)
      .def_readwrite("env", &train::TmaRunArguments::env)
      .def_readwrite("body", &train::TmaRunArguments::body)
      .def_readwrite("student", &train::TmaRunArguments::student)
      .def_readwrite("teacher", &train::TmaRunArguments::teacher)
      .def_readwrite("expert_knowledge", &train::TmaRunArguments::expert_knowledge)
      .def_readwrite("test_set", &train::TmaRunArguments::test_set)
      .def_readwrite("out", &train::TmaRunArguments::out)
      .def_readwrite("teacher_params", &train::TmaRunArguments::teacher_params)
      .def_readwrite("hp", &train::TmaRunArguments::hp)
      .def_readwrite("steps", &train::TmaRunArguments::steps)
      .def_readwrite("test_every", &train::TmaRunArguments::test_every)
      .def_readwrite("nb_test_episodes", &train::TmaRunArguments::nb_test_episodes)
      .def_readwrite("reset_frequency", &train::TmaRunArguments::reset_frequency)
      .def_readwrite("keep_periodical_task_samples",
                     &train::TmaRunArguments::keep_periodical_task_samples)
      .def_readwrite("seed", &train::TmaRunArguments::seed)
      .def_readwrite("shuffle_dimensions", &train::TmaRunArguments::shuffle_dimensions)
      .def_readwrite("scale_reward", &train::TmaRunArguments::scale_reward)
      .def_readwrite("resume", &train::TmaRunArguments::resume)
      .def_readwrite("overwrite", &train::TmaRunArguments::overwrite)
      .def_readwrite("progress_bar", &train::TmaRunArguments::progress_bar)
      .def_readwrite("env_options", &train::TmaRunArguments::env_options);
}

}  // namespace cradle::python

// cradle.sami.train / evaluate / table: the SaMI learners (src/train/sami/) from Python. The GIL
// is released while C++ trains and evaluates.
#include <filesystem>

#include "python/common.h"
#include "train/sami/sami_experiment.h"

namespace cradle::python {

void bind_sami_learn(py::module_& m) {
  m.def(
      "sami_train",
      [](const std::string& env, const std::string& method, std::uint64_t seed, long steps_per_env,
         const std::map<std::string, std::string>& hyperparameters, const std::string& out,
         bool resume, long checkpoint_every, bool progress_bar) {
        train::SamiTrainOptions o{.env = env,
                                  .method = method,
                                  .seed = seed,
                                  .steps_per_env = steps_per_env,
                                  .hyperparameters = hyperparameters,
                                  .out = out,
                                  .resume = resume,
                                  .checkpoint_every = checkpoint_every,
                                  .progress_bar = progress_bar};
        const train::SamiTrainResult r = without_gil([&] { return train::sami_train(o); });
        py::dict d;
        d["run"] = r.run.string();
        d["steps"] = r.steps;
        d["updates"] = r.updates;
        d["sps"] = r.sps;
        d["gradient_steps_per_s"] = r.gradient_steps_per_s;
        d["last_return"] = r.last_return;
        d["checkpoint"] = r.checkpoint.string();
        return d;
      },
      py::arg("env"), py::arg("method"), py::arg("seed"), py::arg("steps_per_env"),
      py::arg("hyperparameters"), py::arg("out"), py::arg("resume"), py::arg("checkpoint_every"),
      py::arg("progress_bar"));
  m.def(
      "sami_evaluate",
      [](const std::string& run, const std::string& split, int episodes, bool video,
         std::uint64_t seed) {
        const train::SamiEvalResult r = without_gil([&] {
          return train::sami_evaluate(
              {.run = run, .split = split, .episodes = episodes, .video = video, .seed = seed});
        });
        py::list cells;
        for (const train::SamiCell& c : r.cells) {
          py::dict d;
          d["cell"] = c.name;
          d["episodes"] = c.episodes;
          d["success_rate"] = c.success_rate;
          d["mean_return"] = c.mean_return;
          d["std_return"] = c.std_return;
          d["push"] = c.push;
          d["roll"] = c.roll;
          d["pick_and_place"] = c.pick_and_place;
          cells.append(d);
        }
        py::dict d;
        d["split"] = r.split;
        d["success_rate"] = r.success_rate;
        d["mean_return"] = r.mean_return;
        d["cells"] = cells;
        d["json"] = r.json.string();
        d["csv"] = r.csv.string();
        d["contexts"] = r.contexts.string();
        return d;
      },
      py::arg("run"), py::arg("split"), py::arg("episodes"), py::arg("video"), py::arg("seed"));
  m.def(
      "sami_table",
      [](const std::vector<std::string>& runs, const std::string& out) {
        return train::sami_table({runs.begin(), runs.end()}, out);
      },
      py::arg("runs"), py::arg("out") = "");
}

}  // namespace cradle::python

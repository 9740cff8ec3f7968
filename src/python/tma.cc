// `_cradle.TmaEnv`: TeachMyAgent's environments (src/tma/) for python/cradle/tma.py. Observations
// are fresh float32 arrays (the reference's observation space; the env computes in float64 and
// rounds once); render() returns an (H, W, 3) uint8 array.
#include <cstring>

#include "python/common.h"
#include "tma/render.h"
#include "tma/tma_env.h"

namespace cradle::python {

void bind_tma(py::module_& m) {
  using tma::TmaEnv;
  auto obs_array = [](const TmaEnv& env) {
    const auto obs = env.observation();
    py::array_t<float> out(static_cast<py::ssize_t>(obs.size()));
    float* dst = out.mutable_data();
    for (std::size_t i = 0; i < obs.size(); ++i) dst[i] = static_cast<float>(obs[i]);
    return out;
  };
  py::class_<TmaEnv>(m, "TmaEnv", "A TeachMyAgent environment (use cradle.tma.make).")
      .def(py::init([](const std::string& env, const std::string& body, const std::string& lidars,
                       bool movable_creepers, double water_clip, int max_episode_steps,
                       const std::vector<std::pair<std::string, std::string>>& options) {
             tma::TmaOptions o{.env = tma::parse_env_id(env),
                               .body = body,
                               .lidars = lidars,
                               .movable_creepers = movable_creepers,
                               .water_clip = water_clip,
                               .max_episode_steps = max_episode_steps};
             for (const auto& [name, value] : options) tma::set_option(o, name, value);
             return std::make_unique<TmaEnv>(o);
           }),
           py::arg("env"), py::arg("body"), py::arg("lidars") = "",
           py::arg("movable_creepers") = false, py::arg("water_clip") = 20.0,
           py::arg("max_episode_steps") = tma::kMaxEpisodeSteps,
           py::arg("options") = std::vector<std::pair<std::string, std::string>>{},
           "options: (name, text) pairs of the reference's body and Parkour options.")
      .def_property_readonly("observation_size", &TmaEnv::observation_size)
      .def_property_readonly("action_size", &TmaEnv::action_size)
      .def_property_readonly(
          "env_id", [](const TmaEnv& e) { return std::string(env_id_name(e.options().env)); })
      .def_property_readonly("body", [](const TmaEnv& e) { return e.options().body; })
      .def_property_readonly("body_type",
                             [](const TmaEnv& e) { return std::string(kind_name(e.agent().kind)); })
      .def("set_environment", &TmaEnv::set_environment, py::arg("params"),
           "Task parameters as a list of (name, values) pairs.")
      .def(
          "reset",
          [obs_array](TmaEnv& e, std::optional<std::uint64_t> seed) {
            e.reset(seed);
            return obs_array(e);
          },
          py::arg("seed") = py::none())
      .def(
          "step",
          [obs_array](TmaEnv& e, const std::vector<double>& action) {
            const tma::TmaStep r = e.step(action);
            return py::make_tuple(obs_array(e), r.reward, r.terminated, r.truncated, r.success);
          },
          py::arg("action"))
      .def(
          "render",
          [](const TmaEnv& e, int width, int height, bool lidars) {
            std::vector<std::uint8_t> rgb;
            tma::render(e, width, height, lidars, rgb);
            py::array_t<std::uint8_t> out({height, width, 3});
            std::memcpy(out.mutable_data(), rgb.data(), rgb.size());
            return out;
          },
          py::arg("width") = 600, py::arg("height") = 400, py::arg("lidars") = true)
      .def_property_readonly("motors_torque", [](const TmaEnv& e) { return e.agent().torque; })
      .def_property_readonly("torque_penalty",
                             [](const TmaEnv& e) { return e.agent().torque_penalty; })
      .def_property_readonly("body_parts", [](const TmaEnv& e) { return e.agent().parts.size(); })
      .def_property_readonly("steps_under_water", &TmaEnv::steps_under_water)
      .def_property_readonly("steps_outside_water", &TmaEnv::steps_outside_water)
      .def_property_readonly("dead", &TmaEnv::dead)
      // The observation as the env computed it (float64), before the rounding to float32.
      .def("observation_float64",
           [](const TmaEnv& e) {
             const auto obs = e.observation();
             return py::array_t<double>(static_cast<py::ssize_t>(obs.size()), obs.data());
           })
      .def_property_readonly("episode_return", &TmaEnv::episode_return)
      .def_property_readonly("episode_steps", &TmaEnv::episode_steps)
      .def("head_position",
           [](const TmaEnv& e) {
             const b2Vec2 p = e.agent().head->GetPosition();
             return py::make_tuple(p.x, p.y);
           })
      .def("terrain", [](const TmaEnv& e) {
        const tma::Scene& s = e.scene();
        return py::make_tuple(s.xs, s.ground, s.ceiling, s.water_y);
      });
  m.def("tma_embodiments", [] { return tma::embodiment_names(); });
  m.def("tma_option_names", [] { return tma::option_names(); });
  m.def("tma_data_dir", [] { return tma::data_dir().string(); });
  bind_tma_run(m);
}

}  // namespace cradle::python

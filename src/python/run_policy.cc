// A run's trained policy for Python (train/run_policy.h): `_cradle.load_run_policy` and its
// `RunPolicy`, which python/cradle/policy.py wraps as cradle.load_policy(run_folder).
#include "train/run_policy.h"

#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "core/error.h"
#include "python/common.h"

namespace cradle::python {
namespace {

// The policy and what converting an observation dict needs.
class PyRunPolicy {
 public:
  PyRunPolicy(const std::string& run_folder, const std::string& checkpoint, bool sampled)
      : policy_(
            without_gil([&] { return train::load_run_policy(run_folder, checkpoint, sampled); })),
        entries_(entries_of(policy_.observation_space())),
        observation_(policy_.observation_space()) {}

  const train::RunPolicy& policy() const { return policy_; }

  // The action (float64, the action space's size) for one observation dict as the env returns
  // it; every key of the space must be there with its number of values (extra keys are ignored).
  py::array_t<double> act(const py::object& observation) {
    if (!py::isinstance<py::dict>(observation)) {
      throw py::value_error("observation must be a dict of arrays as the env returns it (keys " +
                            key_list() + "), not " +
                            std::string(py::str(py::type::of(observation).attr("__name__"))));
    }
    const py::dict obs = observation.cast<py::dict>();
    for (size_t k = 0; k < entries_.size(); ++k) copy_in(obs, static_cast<int>(k));
    py::array_t<double> action(policy_.action_space().size());
    const std::span<double> out(action.mutable_data(), static_cast<size_t>(action.size()));
    {
      py::gil_scoped_release release;
      policy_.act(observation_, out);
    }
    return action;
  }

  void new_episode() { policy_.new_episode(); }

 private:
  std::string key_list() const {
    std::string keys;
    for (const Entry& e : entries_) keys += (keys.empty() ? "" : ", ") + e.key;
    return keys;
  }

  // Copies obs[key] of entry k into the observation buffers, converted to the key's dtype.
  void copy_in(const py::dict& obs, int k) {
    const Entry& e = entries_[k];
    if (!obs.contains(e.key.c_str())) {
      throw py::value_error("observation has no key '" + e.key + "'; expected the keys " +
                            key_list());
    }
    const py::handle value = obs[e.key.c_str()];
    // Converted to the key's dtype (numpy's rules, as the env's own arrays need none).
    const DType dtype = policy_.observation_space().entries[static_cast<size_t>(k)].second.dtype;
    py::array a;
    void* target = nullptr;
    switch (dtype) {
      case DType::kFloat32:
        a = py::array_t<float, py::array::c_style | py::array::forcecast>::ensure(value);
        target = observation_.f32(k).data();
        break;
      case DType::kFloat64:
        a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(value);
        target = observation_.f64(k).data();
        break;
      case DType::kUInt8:
        a = py::array_t<std::uint8_t, py::array::c_style | py::array::forcecast>::ensure(value);
        target = observation_.u8(k).data();
        break;
    }
    py::ssize_t expected = 1;
    for (py::ssize_t d : e.shape) expected *= d;
    if (!a || a.size() != expected) {
      throw py::value_error("observation '" + e.key + "' has " +
                            (a ? std::to_string(a.size()) + " values" : "no numbers") +
                            ", expected " + std::to_string(expected) + " (" +
                            std::string(dtype_name(dtype)) +
                            "); give one observation, not a batch");
    }
    std::memcpy(target, a.data(), e.bytes);
  }

  train::RunPolicy policy_;
  std::vector<Entry> entries_;
  envs::ObservationBuffers observation_;
};

}  // namespace

void bind_run_policy(py::module_& m) {
  py::class_<PyRunPolicy>(m, "RunPolicy", "A run's trained policy (use cradle.load_policy).")
      .def(py::init<const std::string&, const std::string&, bool>(), py::arg("run_folder"),
           py::arg("checkpoint"), py::arg("sampled"))
      .def("act", &PyRunPolicy::act, py::arg("observation"), "The action for one observation dict.")
      .def("new_episode", &PyRunPolicy::new_episode, "The next observation starts a new episode.")
      .def_property_readonly("env", [](const PyRunPolicy& p) { return p.policy().run().env; })
      .def_property_readonly("family", [](const PyRunPolicy& p) { return p.policy().run().family; })
      .def_property_readonly("algorithm",
                             [](const PyRunPolicy& p) { return p.policy().run().algorithm; })
      .def_property_readonly("seed", [](const PyRunPolicy& p) { return p.policy().run().seed; })
      .def_property_readonly("checkpoint",
                             [](const PyRunPolicy& p) { return p.policy().checkpoint().string(); })
      .def_property_readonly("steps", [](const PyRunPolicy& p) { return p.policy().steps(); })
      .def_property_readonly("sampled", [](const PyRunPolicy& p) { return p.policy().sampled(); })
      .def_property_readonly(
          "observation_space",
          [](const PyRunPolicy& p) { return space_list(p.policy().observation_space()); })
      .def_property_readonly("action_space", [](const PyRunPolicy& p) {
        return box_tuple(p.policy().action_space());
      });
}

}  // namespace cradle::python

// Vector envs, training, evaluation and policies for Python: `_cradle.VecEnv`, `train`,
// `evaluate`, `Policy`, `training_score`.
//
// Python callables run inside C++ loops (intrinsic rewards, evaluation policies) through hooks
// that take the GIL for each call; the loops themselves run with the GIL released.
#include <chrono>
#include <cstdint>
#include <cstring>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "envs/babybench.h"
#include "envs/registry.h"
#include "eval/log_check.h"
#include "eval/scores.h"
#include "learn/proc_vector_env.h"
#include "learn/vector_env.h"
#include "python/common.h"
#include "python/python_teacher.h"
#include "train/babybench_vector.h"
#include "train/env_vector.h"
#include "train/evaluation.h"
#include "train/run_policy.h"
#include "train/trainer.h"

namespace cradle::python {
namespace {

using Actions = py::array_t<double, py::array::c_style | py::array::forcecast>;

// Numpy object array holding `items` (Gymnasium's vector infos for non-numeric values); None
// for null items. Filled through its data pointer: numpy zero-fills object arrays (null slots).
py::array object_array(std::vector<py::object> items) {
  const std::vector<py::ssize_t> shape = {static_cast<py::ssize_t>(items.size())};
  py::array out(py::dtype("O"), shape);
  auto** slots = static_cast<PyObject**>(out.mutable_data());
  for (size_t i = 0; i < items.size(); ++i) {
    PyObject* value = items[i] ? items[i].release().ptr() : Py_NewRef(Py_None);
    Py_XDECREF(slots[i]);
    slots[i] = value;
  }
  return out;
}

}  // namespace

// N envs stepped by C++ threads (or, BabyBench, worker processes), with batched numpy
// observations: a BabyBench config's envs, or any registry id's (envs/registry.h). Next-step
// autoreset (Gymnasium 1.x's default) or, with same_step, Stable-Baselines3's
// convention: an env whose episode ends is reset in the same call, its last observation and info
// kept in the infos as "final_obs" / "final_info".
class PyVecEnv {
 public:
  // procs > 0: the envs in that many worker processes (learn::ProcVecEnv) instead of threads.
  PyVecEnv(const Config& config, int num_envs, int threads, bool training, std::uint64_t seed,
           bool same_step, int procs)
      : same_step_(same_step) {
    if (num_envs < 1) throw py::value_error("num_envs must be at least 1");
    if (procs < 0) throw py::value_error("procs must be 0 (threads) or more");
    {
      py::gil_scoped_release release;
      if (procs > 0) {
        auto vec = train::make_babybench_proc_vec_env(config, num_envs, procs, training, seed);
        procs_ = vec.get();
        vec_ = std::move(vec);
      } else {
        auto vec = train::make_babybench_vec_env(config, num_envs, threads, training, seed);
        threaded_ = vec.get();
        vec_ = std::move(vec);
      }
    }
    entries_ = entries_of(vec_->observation_space());
  }

  // The envs of a registry id: env i made by the id's factory with index i and seed
  // ThreadedVecEnv::env_seed(seed, i), all sharing what the factory compiled once.
  // procs > 0: in that many worker processes, as for a config.
  PyVecEnv(const std::string& id, int num_envs, int threads, std::uint64_t seed, bool same_step,
           const envs::EnvOptions& options, int procs)
      : same_step_(same_step) {
    if (num_envs < 1) throw py::value_error("num_envs must be at least 1");
    if (procs < 0) throw py::value_error("procs must be 0 (threads) or more");
    {
      py::gil_scoped_release release;
      const envs::EnvMaker maker = envs::env_maker(id, options);
      const auto make = [&](int i) { return maker(i, learn::ThreadedVecEnv::env_seed(seed, i)); };
      if (procs > 0) {
        auto vec = std::make_unique<learn::ProcVecEnv>(num_envs, make, procs);
        procs_ = vec.get();
        vec_ = std::move(vec);
      } else {
        auto vec = std::make_unique<learn::ThreadedVecEnv>(num_envs, make, threads);
        threaded_ = vec.get();
        vec_ = std::move(vec);
      }
    }
    entries_ = entries_of(vec_->observation_space());
  }

  // Reset options (a teacher's task parameters) for every env's following resets.
  void set_reset_options(const envs::ResetOptions& options) {
    if (!threaded_) throw UserError("reset options are not supported with worker processes");
    for (int i = 0; i < num_envs(); ++i) vec_->env(i).set_reset_options(options);
  }

  int num_envs() const { return vec_->num_envs(); }
  int threads() const { return threaded_ ? threaded_->threads() : 0; }
  int procs() const { return procs_ ? procs_->procs() : 0; }
  learn::VecEnv& vec() { return *vec_; }

  py::tuple reset(std::uint64_t seed) {
    py::dict obs = allocate();
    {
      py::gil_scoped_release release;
      vec_->reset(seed);
      gather();
    }
    return py::make_tuple(obs, infos());
  }

  py::tuple step(const Actions& actions) {
    const py::ssize_t n = static_cast<py::ssize_t>(num_envs()) * vec_->action_space().size();
    if (actions.size() != n) {
      throw py::value_error("actions have " + std::to_string(actions.size()) +
                            " values, expected " + std::to_string(num_envs()) + " x " +
                            std::to_string(vec_->action_space().size()));
    }
    py::dict obs = allocate();
    {
      py::gil_scoped_release release;
      const auto start = std::chrono::steady_clock::now();
      vec_->step({actions.data(), static_cast<size_t>(n)});
      stepping_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (!same_step_) gather();
    }
    const int envs = num_envs();
    py::array_t<double> rewards(envs);
    py::array_t<bool> terminated(envs), truncated(envs);
    bool any_ended = false;
    for (int i = 0; i < envs; ++i) {
      rewards.mutable_at(i) = vec_->rewards()[i];
      terminated.mutable_at(i) = vec_->terminated()[i] != 0;
      truncated.mutable_at(i) = vec_->truncated()[i] != 0;
      any_ended = any_ended || terminated.at(i) || truncated.at(i);
    }
    py::dict info;
    if (same_step_) {
      // The ended envs' last observation and info, then their reset, then the batch.
      std::vector<py::object> final_obs(envs), final_info(envs);
      py::array_t<bool> mask(envs);
      for (int i = 0; i < envs; ++i) {
        const bool ended = terminated.at(i) || truncated.at(i);
        mask.mutable_at(i) = ended;
        if (ended) {
          py::dict o;
          for (size_t k = 0; k < entries_.size(); ++k) {
            o[entries_[k].key.c_str()] =
                copy_array(entries_[k], vec_->observation(i).bytes(static_cast<int>(k)));
          }
          final_obs[i] = o;
          final_info[i] = info_dict(vec_->info(i));
        }
      }
      {
        py::gil_scoped_release release;
        if (any_ended) threaded_ ? threaded_->reset_ended() : procs_->reset_ended();
        gather();
      }
      info = infos();
      info["final_obs"] = object_array(std::move(final_obs));
      info["_final_obs"] = mask;
      info["final_info"] = object_array(std::move(final_info));
      info["_final_info"] = mask;
    } else {
      info = infos();
    }
    return py::make_tuple(obs, rewards, terminated, truncated, info);
  }

  // Seconds for `steps` C++ vector steps over actions (steps x num_envs x action dim), with no
  // batching into numpy: the baseline of the vector throughput benchmark.
  double bench(const Actions& actions) {
    const py::ssize_t per_step = static_cast<py::ssize_t>(num_envs()) * vec_->action_space().size();
    if (actions.ndim() != 3 || actions.shape(1) * actions.shape(2) != per_step) {
      throw py::value_error("actions must have shape (steps, num_envs, action dim)");
    }
    const double* a = actions.data();
    const py::ssize_t steps = actions.shape(0);
    py::gil_scoped_release release;
    const auto start = std::chrono::steady_clock::now();
    for (py::ssize_t t = 0; t < steps; ++t)
      vec_->step({a + t * per_step, static_cast<size_t>(per_step)});
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }

  // Wall seconds spent inside the C++ vector's step() calls made by step(): the rest of a Python
  // loop's time is the binding's and Python's overhead.
  double stepping_seconds() const { return stepping_; }
  void clear_stepping() { stepping_ = 0; }

  // The env i's info dict.
  py::dict info(int i) const { return info_dict(vec_->info(i)); }

  void close() {
    if (!vec_) return;
    for (int i = 0; i < vec_->num_envs(); ++i) vec_->env(i).close();
  }

 private:
  // One fresh (num_envs, *shape) array per key; gather() fills them.
  py::dict allocate() {
    py::dict obs;
    pointers_.clear();
    for (const Entry& e : entries_) {
      std::vector<py::ssize_t> shape = {num_envs()};
      shape.insert(shape.end(), e.shape.begin(), e.shape.end());
      py::array a(e.dtype, shape);
      pointers_.push_back(static_cast<std::byte*>(a.mutable_data()));
      obs[e.key.c_str()] = a;
    }
    return obs;
  }
  // Copies every env's observation into the arrays of the last allocate(). Needs no GIL: the
  // arrays exist already and only their memory is written.
  void gather() {
    for (int i = 0; i < num_envs(); ++i) {
      const envs::ObservationBuffers& o = vec_->observation(i);
      for (size_t k = 0; k < entries_.size(); ++k) {
        std::memcpy(pointers_[k] + i * entries_[k].bytes, o.bytes(static_cast<int>(k)).data(),
                    entries_[k].bytes);
      }
    }
  }
  // Gymnasium vector infos: one array per key plus its "_key" mask (every env has every key).
  py::dict infos() const {
    const int envs = num_envs();
    py::dict out;
    py::array_t<bool> all(envs);
    for (int i = 0; i < envs; ++i) all.mutable_at(i) = true;
    auto put = [&](const std::string& key, py::object value) {
      out[key.c_str()] = value;
      out[("_" + key).c_str()] = all;
    };
    // One array per published key: lists as an object array, numbers by their type.
    const envs::Info& first = vec_->info(0);
    for (int k = 0; k < first.size(); ++k) {
      if (!first.published(k)) continue;
      switch (first.type(k)) {
        case envs::InfoType::kIntList: {
          std::vector<py::object> lists(envs);
          for (int i = 0; i < envs; ++i) lists[i] = info_value(vec_->info(i), k);
          put(first.name(k), object_array(std::move(lists)));
          break;
        }
        case envs::InfoType::kBool: {
          py::array_t<bool> a(envs);
          for (int i = 0; i < envs; ++i) a.mutable_at(i) = vec_->info(i).flag(k);
          put(first.name(k), a);
          break;
        }
        case envs::InfoType::kInt: {
          py::array_t<std::int64_t> a(envs);
          for (int i = 0; i < envs; ++i) {
            a.mutable_at(i) = static_cast<std::int64_t>(vec_->info(i).number(k));
          }
          put(first.name(k), a);
          break;
        }
        case envs::InfoType::kReal: {
          py::array_t<double> a(envs);
          for (int i = 0; i < envs; ++i) a.mutable_at(i) = vec_->info(i).number(k);
          put(first.name(k), a);
          break;
        }
      }
    }
    py::array_t<std::int64_t> steps(envs);
    for (int i = 0; i < envs; ++i) steps.mutable_at(i) = vec_->info(i).steps;
    put("steps", steps);
    return out;
  }

  bool same_step_;
  std::unique_ptr<learn::VecEnv> vec_;
  learn::ThreadedVecEnv* threaded_ = nullptr;  // one of these two is vec_
  learn::ProcVecEnv* procs_ = nullptr;
  std::vector<Entry> entries_;
  std::vector<std::byte*> pointers_;
  double stepping_ = 0;
};

namespace {

// One Python reward term: fn(obs, action, info) or fn(obs) (wants_info false), times weight.
struct PyTerm {
  py::object fn;
  double weight = 1;
  bool full = true;  // called with (obs, action, info); else with (obs) only
};

// The reward hook of cradle.train: takes the GIL once per vector step, checks for Ctrl-C, and
// adds weight x fn(...) of every term to every env's reward. Observations are passed as read-only
// views of the envs' buffers, valid only during the call.
class PyRewardHook {
 public:
  explicit PyRewardHook(std::vector<PyTerm> terms) : terms_(std::move(terms)) {}

  void operator()(const learn::VecEnv& env, std::span<const double> actions,
                  std::span<double> rewards) {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    if (terms_.empty()) return;
    const int envs = env.num_envs();
    // Views of each env's buffers, made at its first call (an async batch holds some envs).
    for (int i = 0; i < envs; ++i) {
      const size_t id = env.env_id(i);
      if (id < obs_.size() && obs_[id]) continue;
      if (entries_.empty()) entries_ = entries_of(env.observation_space());
      if (id >= obs_.size()) obs_.resize(id + 1);
      py::dict d;
      for (size_t k = 0; k < entries_.size(); ++k) {
        d[entries_[k].key.c_str()] =
            view_array(entries_[k], env.observation(i).bytes(static_cast<int>(k)), py::tuple());
      }
      obs_[id] = d;
    }
    const size_t dim = actions.size() / envs;
    for (int i = 0; i < envs; ++i) {
      py::object action, info;
      for (const PyTerm& t : terms_) {
        double r = 0;
        if (t.full) {
          if (!action) {
            action =
                view_doubles(actions.data() + i * dim, static_cast<py::ssize_t>(dim), py::tuple());
            info = info_dict(env.info(i));
          }
          r = t.fn(obs_[env.env_id(i)], action, info).cast<double>();
        } else {
          r = t.fn(obs_[env.env_id(i)]).cast<double>();
        }
        rewards[i] += t.weight * r;
      }
    }
  }

 private:
  std::vector<PyTerm> terms_;
  std::vector<Entry> entries_;
  std::vector<py::object> obs_;  // per env id: views of its observation buffers (dicts)
};

// A Python policy for evaluation: fn(obs dict) -> action, with fresh observation arrays.
// The callable is held through a shared_ptr: copies of the std::function made by C++ code
// without the GIL then never touch Python reference counts.
train::Policy python_policy(py::object callable) {
  auto fn = std::make_shared<py::object>(std::move(callable));
  auto entries = std::make_shared<std::vector<Entry>>();
  return [fn, entries](const envs::BabyBenchEnv& env, std::span<double> action) {
    py::gil_scoped_acquire gil;
    if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    if (entries->empty()) *entries = entries_of(env.observation_space());
    py::dict obs;
    for (size_t k = 0; k < entries->size(); ++k) {
      const Entry& e = (*entries)[k];
      obs[e.key.c_str()] = copy_array(e, env.observation().bytes(static_cast<int>(k)));
    }
    const Actions a = Actions::ensure((*fn)(obs));
    if (!a || static_cast<size_t>(a.size()) != action.size()) {
      throw py::value_error("policy must return " + std::to_string(action.size()) +
                            " action values");
    }
    std::memcpy(action.data(), a.data(), sizeof(double) * action.size());
  };
}

// A trained checkpoint's deterministic policy (cradle.load_policy).
struct PyPolicy {
  train::Policy policy;
  bool sampled = false;  // actions drawn from the policy's distribution instead of its mean
  int action_dim = 0;
};

}  // namespace

void bind_learn(py::module_& m) {
  py::class_<PyVecEnv>(m, "VecEnv",
                       "Envs stepped by C++ threads or processes (use cradle.VectorEnv).")
      .def(py::init<const Config&, int, int, bool, std::uint64_t, bool, int>(), py::arg("config"),
           py::arg("num_envs"), py::arg("threads") = 0, py::arg("training") = false,
           py::arg("seed") = 0, py::arg("same_step") = false, py::arg("procs") = 0)
      .def_static(
          "for_id",
          [](const std::string& id, int num_envs, int threads, std::uint64_t seed, bool same_step,
             const envs::EnvOptions& options, int procs) {
            return std::make_unique<PyVecEnv>(id, num_envs, threads, seed, same_step, options,
                                              procs);
          },
          py::arg("id"), py::arg("num_envs"), py::arg("threads") = 0, py::arg("seed") = 0,
          py::arg("same_step") = false, py::arg("options") = envs::EnvOptions{},
          py::arg("procs") = 0,
          "The envs of a registry id (env i: index i, seed env_seed(seed, i)).")
      .def("set_reset_options", &PyVecEnv::set_reset_options, py::arg("options"))
      .def("reset", &PyVecEnv::reset, py::arg("seed"))
      .def("step", &PyVecEnv::step, py::arg("actions"))
      .def("bench", &PyVecEnv::bench, py::arg("actions"))
      .def("info", &PyVecEnv::info, py::arg("env"))
      .def_property_readonly("stepping_seconds", &PyVecEnv::stepping_seconds)
      .def("clear_stepping", &PyVecEnv::clear_stepping)
      .def("close", &PyVecEnv::close)
      .def_property_readonly("num_envs", &PyVecEnv::num_envs)
      .def_property_readonly("threads", &PyVecEnv::threads)
      .def_property_readonly("procs", &PyVecEnv::procs)
      .def_property_readonly("observation_space",
                             [](PyVecEnv& v) { return space_list(v.vec().observation_space()); })
      .def_property_readonly("action_space",
                             [](PyVecEnv& v) { return box_tuple(v.vec().action_space()); });

  m.def("env_seed", &learn::ThreadedVecEnv::env_seed, py::arg("seed"), py::arg("index"),
        "The seed of env `index` of a vector seeded with `seed` (its reset(seed) and make).");

  m.def(
      "train",
      [](const Config& config, const std::string& algorithm, const std::string& intrinsic,
         long steps, int envs, int threads, int async_batch, std::uint64_t seed, bool resume,
         bool randomize_start, long checkpoint_every,
         const std::map<std::string, std::string>& hyperparameters, int eval_episodes,
         int eval_duration, bool eval_render, bool compare_random, bool progress_bar,
         const py::list& terms, const std::string& env, const std::string& save_dir,
         const std::string& task_space, const py::object& teacher, bool overwrite, int procs,
         long reset_every) {
        // An env id of any family: a BabyBench id trains its config, the others by id (their
        // run folder: save_dir, else results/<id>).
        Config run_config = config;
        std::string by_id;
        if (!env.empty()) {
          if (const std::optional<Config> c = train::babybench_config(env)) {
            run_config = *c;
          } else {
            by_id = train::registered_env_id(env);
            run_config.save_dir = "results/" + by_id;
          }
        }
        if (!save_dir.empty()) run_config.save_dir = save_dir;
        train::TrainOptions o{.env = by_id,
                              .algorithm = algorithm,
                              .intrinsic = intrinsic,
                              .steps = steps,
                              .envs = envs,
                              .threads = threads,
                              .async_batch = async_batch,
                              .seed = seed,
                              .resume = resume,
                              .randomize_start = randomize_start,
                              .checkpoint_every = checkpoint_every,
                              .hyperparameters = hyperparameters,
                              .eval_episodes = eval_episodes,
                              .eval_duration = eval_duration,
                              .eval_render = eval_render,
                              .compare_random = compare_random,
                              .progress_bar = progress_bar};
        o.task_space = task_space;
        // A teacher by name, or a Python object (its protocol checked before anything runs).
        std::optional<PythonTeacher> own_teacher;
        if (py::isinstance<py::str>(teacher)) {
          o.teacher = teacher.cast<std::string>();
        } else if (!teacher.is_none()) {
          own_teacher.emplace(teacher);
          o.teacher_factory = own_teacher->factory();
        }
        o.overwrite = overwrite;
        o.procs = procs;
        o.reset_every = reset_every;
        std::vector<PyTerm> py_terms;
        for (const py::handle t : terms) {
          const py::tuple tt = py::reinterpret_borrow<py::tuple>(t);
          py_terms.push_back({tt[0].cast<py::object>(), tt[1].cast<double>(), tt[2].cast<bool>()});
        }
        auto hook = std::make_shared<PyRewardHook>(std::move(py_terms));
        o.reward_hook = [hook](const learn::VecEnv& env, std::span<const double> actions,
                               std::span<double> rewards) { (*hook)(env, actions, rewards); };
        const train::TrainResult r = [&] {
          try {
            return without_gil([&] { return train::train(run_config, o); });
          } catch (const PythonTeacherError&) {
            // The teacher's own exception, as the cause of a RuntimeError with its message.
            if (own_teacher) own_teacher->raise_if_failed();
            throw;
          }
        }();
        py::dict out;
        out["steps"] = r.steps;
        out["seconds"] = r.seconds;
        out["steps_per_second"] = r.steps_per_second;
        out["training_score"] = r.training_score ? py::cast(*r.training_score) : py::none();
        out["checkpoint"] = r.checkpoint.string();
        out["run"] = run_config.save_dir;
        out["evaluation"] = r.evaluation ? py::cast(r.evaluation->to_json().dump()) : py::none();
        out["random_evaluation"] =
            r.random_evaluation ? py::cast(r.random_evaluation->to_json().dump()) : py::none();
        return out;
      },
      py::arg("config"), py::arg("algorithm"), py::arg("intrinsic"), py::arg("steps"),
      py::arg("envs"), py::arg("threads"), py::arg("async_batch"), py::arg("seed"),
      py::arg("resume"), py::arg("randomize_start"), py::arg("checkpoint_every"),
      py::arg("hyperparameters"), py::arg("eval_episodes"), py::arg("eval_duration"),
      py::arg("eval_render"), py::arg("compare_random"), py::arg("progress_bar"), py::arg("terms"),
      py::arg("env") = "", py::arg("save_dir") = "", py::arg("task_space") = "",
      py::arg("teacher") = "", py::arg("overwrite") = false, py::arg("procs") = 0,
      py::arg("reset_every") = 0,
      "Trains with the C++ learners (see cradle.train). Python reward terms are (fn, weight, "
      "full) tuples; teacher is a teacher's name or a Python teacher object.");

  py::class_<PyPolicy>(m, "Policy", "A trained checkpoint's deterministic policy.")
      .def_readonly("action_dim", &PyPolicy::action_dim);
  m.def(
      "load_policy",
      [](const Config& config, const std::string& checkpoint, bool stochastic) {
        return PyPolicy{.policy = without_gil(
                            [&] { return train::load_policy(config, checkpoint, stochastic); }),
                        .sampled = stochastic};
      },
      py::arg("config"), py::arg("checkpoint"), py::arg("stochastic"));

  m.def(
      "evaluate",
      [](const Config& config, int episodes, int duration, bool render, std::uint64_t seed,
         const std::string& video_extension, bool quiet, const py::object& policy,
         bool stochastic) {
        train::EvaluationOptions o{.episodes = episodes,
                                   .duration = duration,
                                   .render = render,
                                   .seed = seed,
                                   .video_extension = video_extension,
                                   .quiet = quiet};
        train::Policy p;
        if (py::isinstance<PyPolicy>(policy)) {
          const PyPolicy& loaded = policy.cast<const PyPolicy&>();
          p = loaded.policy;
          o.policy_actions = loaded.sampled ? "sampled" : "mean";
        } else if (py::isinstance<py::str>(policy)) {
          const std::string checkpoint = policy.cast<std::string>();  // with the GIL
          p = without_gil([&] { return train::load_policy(config, checkpoint, stochastic); });
          o.policy_actions = stochastic ? "sampled" : "mean";
        } else if (!policy.is_none()) {
          p = python_policy(policy);
          o.policy_actions = "custom";
        }
        return without_gil([&] { return train::evaluate(config, o, p); }).to_json().dump();
      },
      py::arg("config"), py::arg("episodes"), py::arg("duration"), py::arg("render"),
      py::arg("seed"), py::arg("video_extension"), py::arg("quiet"), py::arg("policy"),
      py::arg("stochastic"), "Runs the evaluation episodes; returns the report as JSON text.");

  m.def(
      "training_score",
      [](const std::string& behavior, const std::string& entries_json) -> py::object {
        const std::optional<Behavior> b = behavior_from_name(behavior);
        if (!b) throw UserError("unknown behavior '" + behavior + "'");
        const nlohmann::json j = nlohmann::json::parse(entries_json, nullptr, false);
        if (!j.is_array()) throw UserError("training log: expected a list of entries");
        const std::vector<nlohmann::json> entries(j.begin(), j.end());
        eval::check_training_entries(entries, *b);
        const std::optional<double> s = eval::training_score(*b, entries);
        return s ? py::cast(*s) : py::none();
      },
      py::arg("behavior"), py::arg("entries_json"),
      "The reference's training score of a list of log entries (JSON text); None for none.");
}

}  // namespace cradle::python

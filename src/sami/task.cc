#include "sami/task.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

#include "core/error.h"
#include "sami/envs/env_def.h"

namespace cradle::sami {
namespace {

std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%g", v);
  return buf;
}

std::string range_text(const ValueRange& r) {
  return (r.open_low ? "(" : "[") + number_text(r.low) + ", " + number_text(r.high) + "]";
}

// `where`: the set's place ("sets.yml: task_sets[0]", "Ant task set 0"); `what`: mass or
// damping.
void check_factors(const Values& values, const std::string& where, const std::string& what,
                   const ValueRange& range) {
  const std::string expected = "expected " + what + " factors in " + range_text(range);
  if (values.empty()) throw UserError(where + "." + what + " is an empty list; " + expected);
  for (double v : values) {
    if (!range.contains(v)) {
      throw UserError(where + "." + what + ": " + what + " factor " + number_text(v) +
                      " is out of range; " + expected);
    }
  }
}

void validate_set(EnvId id, const TaskSet& t, const std::string& where) {
  const std::string env(env_name(id));
  const Varies v = env_varies(id);
  if (!v.mass && t.mass != Values{1.0}) throw UserError(where + ": " + env + " does not vary mass");
  if (!v.damping && t.damping != Values{1.0}) {
    throw UserError(where + ": " + env + " does not vary damping");
  }
  check_factors(t.mass, where, "mass", kMassFactors);
  check_factors(t.damping, where, "damping", kDampingFactors);
  if (!v.cells && !t.cells.empty()) {
    throw UserError(where + ": " + env + " has no friction x mass cells");
  }
  if (v.cells && t.cells.empty()) {
    throw UserError(where + ": " + env +
                    " has no cells in this task set; expected cells: [[friction, mass], ...]");
  }
  for (const auto& [f, m] : t.cells) {
    if (!kTableFriction.contains(f) || !kCubeMass.contains(m)) {
      throw UserError(where + ".cells: cell [" + number_text(f) + ", " + number_text(m) +
                      "] is out of range; expected table friction in " +
                      range_text(kTableFriction) + " and cube mass in " + range_text(kCubeMass) +
                      " kg");
    }
  }
  if (v.cripple_units == 0 && !t.cripple.empty()) {
    throw UserError(where + ": " + env + " cannot be crippled");
  }
  for (const auto& choice : t.cripple) {
    const std::set<int> unique(choice.begin(), choice.end());
    if (unique.size() != choice.size() || static_cast<int>(choice.size()) > v.max_crippled) {
      throw UserError(where + ".cripple: " + env + "'s cripple choice must list at most " +
                      std::to_string(v.max_crippled) + " distinct joints");
    }
    for (int u : choice) {
      if (u < 0 || u >= v.cripple_units) {
        throw UserError(where + ".cripple: " + env + "'s cripple index " + std::to_string(u) +
                        " is out of range; expected 0.." + std::to_string(v.cripple_units - 1));
      }
    }
  }
}

template <class T>
T read(const YAML::Node& node, const std::string& where, const char* expected) {
  try {
    return node.as<T>();
  } catch (const YAML::Exception&) {
    throw UserError(where + " is not " + expected);
  }
}

}  // namespace

std::vector<TaskSet> quadrants(const Values& low, const Values& high) {
  std::vector<TaskSet> sets;
  for (const Values* m : {&low, &high}) {
    for (const Values* d : {&low, &high}) sets.push_back({.mass = *m, .damping = *d});
  }
  return sets;
}

std::vector<TaskSet> mass_groups(const std::vector<Values>& groups, const Cripples& cripple,
                                 bool mask) {
  std::vector<TaskSet> sets;
  for (const Values& m : groups) sets.push_back({.mass = m, .cripple = cripple, .mask = mask});
  return sets;
}

Cripples pairs(const std::vector<int>& first, const std::vector<int>& second) {
  Cripples out;
  for (int a : first) {
    for (int b : second) {
      if (a < b) out.push_back({a, b});
      if (b < a) out.push_back({b, a});
    }
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

Cripples singles(const std::vector<int>& units) {
  Cripples out;
  for (int u : units) out.push_back({u});
  return out;
}

std::string_view env_name(EnvId id) { return env_def(id).name; }

EnvId env_from_name(std::string_view name) {
  for (EnvId id : all_envs()) {
    if (env_name(id) == name) return id;
  }
  std::string list;
  for (EnvId id : all_envs()) list += (list.empty() ? "" : ", ") + std::string(env_name(id));
  throw UserError("unknown SaMI env '" + std::string(name) + "'; expected one of " + list);
}

Varies env_varies(EnvId id) { return env_def(id).varies; }

std::string_view split_name(Split split) {
  switch (split) {
    case Split::kTrain:
      return "train";
    case Split::kModerate:
      return "moderate";
    case Split::kExtreme:
      return "extreme";
  }
  return "?";
}

Split split_from_name(std::string_view name) {
  for (Split s : {Split::kTrain, Split::kModerate, Split::kExtreme}) {
    if (split_name(s) == name) return s;
  }
  throw UserError("unknown split '" + std::string(name) +
                  "'; expected train, moderate, extreme or a .yml file of task sets");
}

std::string joints_text(const std::vector<int>& joints, std::string_view separator) {
  std::string out;
  for (int j : joints) out += (out.empty() ? "" : std::string(separator)) + std::to_string(j);
  return out;
}

std::vector<TaskSet> one_set_per_env(std::vector<TaskSet> sets) {
  if (sets.size() != 1) return sets;
  const TaskSet& one = sets[0];
  std::vector<TaskSet> out;
  if (one.cripple.size() > 1) {
    for (const auto& choice : one.cripple) {
      TaskSet s = one;
      s.cripple = {choice};
      out.push_back(s);
    }
  } else if (one.mass.size() > 1) {
    for (double m : one.mass) {
      TaskSet s = one;
      s.mass = {m};
      out.push_back(s);
    }
  }
  return out.empty() ? sets : out;
}

std::vector<TaskSet> split_sets(EnvId id, Split split) { return env_def(id).split_sets(split); }

void validate(EnvId id, const std::vector<TaskSet>& sets) {
  const std::string env(env_name(id));
  if (sets.empty()) throw UserError(env + ": no task sets; expected at least one");
  for (size_t i = 0; i < sets.size(); ++i) {
    validate_set(id, sets[i], env + " task set " + std::to_string(i));
  }
}

std::vector<TaskSet> load_task_sets(EnvId id, const std::filesystem::path& file) {
  const std::string name = file.string();
  // A folder or a special file would reach yaml-cpp's stream as an internal read error.
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(file, ec);
  if (!std::filesystem::exists(status)) {
    throw UserError("task-set file '" + name + "' does not exist; expected a .yml file");
  }
  if (!std::filesystem::is_regular_file(status)) {
    throw UserError("task-set file '" + name + "' is " +
                    (std::filesystem::is_directory(status) ? "a folder" : "not a regular file") +
                    "; expected a .yml file");
  }
  YAML::Node root;
  try {
    root = YAML::LoadFile(name);
  } catch (const YAML::BadFile&) {
    throw UserError("cannot read task-set file '" + name + "'");
  } catch (const YAML::Exception& e) {
    throw UserError("task-set file '" + name + "' is not valid YAML: " + e.msg);
  } catch (const std::exception& e) {  // an I/O error while reading
    throw UserError("cannot read task-set file '" + name + "': " + e.what());
  }
  if (!root.IsMap() || !root["task_sets"] || !root["task_sets"].IsSequence()) {
    throw UserError(name + ": expected a top-level key task_sets with a list of task sets");
  }
  std::vector<TaskSet> sets;
  int index = 0;
  for (const YAML::Node& node : root["task_sets"]) {
    const std::string where = name + ": task_sets[" + std::to_string(index++) + "]";
    if (!node.IsMap()) throw UserError(where + " is not a map");
    TaskSet t;
    std::set<std::string> keys;
    for (const auto& kv : node) {
      const std::string key = read<std::string>(kv.first, where + " key", "a string");
      const std::string at = where + "." + key;
      if (!keys.insert(key).second) throw UserError(at + " is given twice; expected each key once");
      if (key == "mass") {
        t.mass = read<Values>(kv.second, at, "a list of numbers");
      } else if (key == "damping") {
        t.damping = read<Values>(kv.second, at, "a list of numbers");
      } else if (key == "cripple") {
        t.cripple = read<Cripples>(kv.second, at, "a list of lists of joint indices");
      } else if (key == "mask") {
        t.mask = read<bool>(kv.second, at, "true or false");
      } else if (key == "cells") {
        for (const auto& cell : read<std::vector<Values>>(kv.second, at, "a list of pairs")) {
          if (cell.size() != 2) throw UserError(at + ": expected [friction, mass] pairs");
          t.cells.push_back({cell[0], cell[1]});
        }
      } else {
        throw UserError(at + " is not a task-set key; expected mass, damping, cripple, mask or " +
                        "cells");
      }
    }
    validate_set(id, t, where);
    sets.push_back(std::move(t));
  }
  if (sets.empty()) {
    throw UserError(name + ": task_sets is an empty list; expected at least one task set");
  }
  return sets;
}

std::vector<TaskSet> task_sets(EnvId id, std::string_view split_or_file) {
  const std::filesystem::path path(split_or_file);
  if (path.extension() == ".yml" || path.extension() == ".yaml") return load_task_sets(id, path);
  return split_sets(id, split_from_name(split_or_file));
}

}  // namespace cradle::sami

// SaMI task sets: the env names, the hidden-parameter value sets an env draws from at each
// reset, and the named splits train / moderate / extreme (tma_sami.md §7.1-7.2), plus user sets
// from YAML.
#pragma once

#include <array>
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "sami/envs/registry.h"

namespace cradle::sami {

// The envs of the registration table (sami/envs/registry.h), in its order.
enum class EnvId {
#define CRADLE_SAMI_ENV_ENUMERATOR(id, file) id,
  CRADLE_SAMI_ENVS(CRADLE_SAMI_ENV_ENUMERATOR)
#undef CRADLE_SAMI_ENV_ENUMERATOR
};
#define CRADLE_SAMI_ENV_ONE(id, file) +1
inline constexpr int kEnvCount = 0 CRADLE_SAMI_ENVS(CRADLE_SAMI_ENV_ONE);
#undef CRADLE_SAMI_ENV_ONE

std::string_view env_name(EnvId id);
std::span<const EnvId> all_envs();
// Throws UserError naming the accepted names.
EnvId env_from_name(std::string_view name);

// What an env lets a task set vary.
struct Varies {
  bool mass = false, damping = false, cells = false;
  int cripple_units = 0;  // crippleable joints (Ant: legs); 0 = none
  int max_crippled = 0;   // most units crippled at once
};
Varies env_varies(EnvId id);

// One set of hidden parameters; each reset draws one value of each list uniformly.
struct TaskSet {
  std::vector<double> mass{1.0};     // mass factors (locomotion)
  std::vector<double> damping{1.0};  // damping factors (locomotion)
  // Crippling choices: each entry lists the joints (Ant: legs) crippled together; an empty entry
  // means none. An empty list means never crippled.
  std::vector<std::vector<int>> cripple;
  bool mask = true;  // crippled actuators masked; false = geometry only (WalkerHopper mode [3])
  // Panda: (table friction, cube mass) cells.
  std::vector<std::array<double, 2>> cells;
};

// The plausible range of a task set's value: [low, high], or (low, high] when open_low. Beyond
// them MuJoCo's integrators diverge (damping x5 makes the humanoids' states NaN) or the task is
// no physical one (a mass x1e-300); validate() refuses values outside them.
struct ValueRange {
  double low, high;
  bool open_low = false;
  bool contains(double v) const { return (open_low ? v > low : v >= low) && v <= high; }  // NaN: no
};
inline constexpr ValueRange kMassFactors{0.01, 100};
inline constexpr ValueRange kDampingFactors{0, 3, true};
inline constexpr ValueRange kTableFriction{0, 100};  // Panda
inline constexpr ValueRange kCubeMass{0.01, 100};    // Panda, kg

enum class Split { kTrain, kModerate, kExtreme };
std::string_view split_name(Split split);
// Throws UserError for a name other than train / moderate / extreme.
Split split_from_name(std::string_view name);

// The env's built-in task sets of a split (one sub-env each in a vector).
std::vector<TaskSet> split_sets(EnvId id, Split split);
// The split a name selects, or the task sets of a YAML file when `name` ends in .yml / .yaml.
std::vector<TaskSet> task_sets(EnvId id, std::string_view split_or_file);
// The sets of a vector, one sub-env each (SaMI's DummyVecEnv): `sets` as they are, except that a
// single set that varies its crippling (or else its mass) is split into one set per choice, so
// that the methods that contrast envs have more than one.
std::vector<TaskSet> one_set_per_env(std::vector<TaskSet> sets);
// Task sets from a YAML file: `task_sets: [{mass: [..], damping: [..], cripple: [[..]], mask: b,
// cells: [[friction, mass]]}]`. Throws UserError naming the file and the set for anything wrong
// (a missing file or a folder, bad YAML, an unknown or repeated key, what validate() refuses).
std::vector<TaskSet> load_task_sets(EnvId id, const std::filesystem::path& file);
// Throws UserError if a set asks for something the env does not vary or holds a value out of its
// plausible range (kMassFactors [0.01, 100], kDampingFactors (0, 3], Panda's kTableFriction
// [0, 100] and kCubeMass [0.01, 100] kg); no list of factors or cells may be empty, and NaN or
// infinity is never in range.
void validate(EnvId id, const std::vector<TaskSet>& sets);

// A crippling choice as text: its joints (Ant: legs) joined by `separator`, e.g. "0,4".
std::string joints_text(const std::vector<int>& joints, std::string_view separator);

// Panda's friction x mass grid cells of each split (§7.2).
std::vector<std::array<double, 2>> panda_cells(Split split);

}  // namespace cradle::sami

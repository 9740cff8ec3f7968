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

namespace cradle::sami {

enum class EnvId {
  kHalfCheetah,
  kAnt,
  kHopper,
  kWalker,
  kSlimHumanoid,
  kHumanoidStandup,
  kCrippleHalfCheetah,
  kCrippleAnt,
  kCrippleHopper,
  kCrippleWalker,
  kWalkerHopper,
  kPandaPush,
};
inline constexpr int kEnvCount = 12;

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

enum class Split { kTrain, kModerate, kExtreme };
std::string_view split_name(Split split);
// Throws UserError for a name other than train / moderate / extreme.
Split split_from_name(std::string_view name);

// The env's built-in task sets of a split (one sub-env each in a vector).
std::vector<TaskSet> split_sets(EnvId id, Split split);
// The split a name selects, or the task sets of a YAML file when `name` ends in .yml / .yaml.
std::vector<TaskSet> task_sets(EnvId id, std::string_view split_or_file);
// Task sets from a YAML file: `task_sets: [{mass: [..], damping: [..], cripple: [[..]], mask: b,
// cells: [[friction, mass]]}]`. Throws UserError for anything wrong.
std::vector<TaskSet> load_task_sets(EnvId id, const std::filesystem::path& file);
// Throws UserError if a set asks for something the env does not vary or holds a bad value.
void validate(EnvId id, const std::vector<TaskSet>& sets);

// A crippling choice as text: its joints (Ant: legs) joined by `separator`, e.g. "0,4".
std::string joints_text(const std::vector<int>& joints, std::string_view separator);

// Panda's friction x mass grid cells of each split (§7.2).
std::vector<std::array<double, 2>> panda_cells(Split split);

}  // namespace cradle::sami

// Per-step information: the named values a task declares (a small typed key -> value map) plus
// the episode's step count. Keys are declared once, when the env is built; values are written in
// place every step (lists keep their capacity), so a step allocates nothing after the first
// episode. Conversions (JSON, Python, evaluation) read the keys generically.
#pragma once

#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace cradle::envs {

enum class InfoType { kBool, kInt, kReal, kIntList };

class Info {
 public:
  // Declares a key and returns its slot. Published keys go to the training log, Python and the
  // evaluation; unpublished ones are signals for learners only (e.g. the contacts of this step).
  // Throws std::logic_error for a key declared twice.
  int declare(std::string name, InfoType type, bool published = true);
  int size() const { return static_cast<int>(slots_.size()); }
  // Slot of a key, -1 if the env does not declare it.
  int find(std::string_view name) const;
  const std::string& name(int slot) const { return slots_[slot].name; }
  InfoType type(int slot) const { return slots_[slot].type; }
  bool published(int slot) const { return slots_[slot].published; }

  // Scalar keys (bool, int, real) as a number; bools are 0 or 1.
  double number(int slot) const { return slots_[slot].number; }
  bool flag(int slot) const { return slots_[slot].number != 0; }
  void set(int slot, double value) { slots_[slot].number = value; }
  void add(int slot, double value) { slots_[slot].number += value; }
  // List keys.
  std::span<const int> list(int slot) const { return slots_[slot].list; }
  std::vector<int>& list(int slot) { return slots_[slot].list; }

  // Zeroes every value and empties every list (keeping its capacity) for a new episode.
  void clear();
  // The published keys and `steps`, as the reference's info dict.
  nlohmann::json to_json() const;

  int steps = 0;  // env steps in this episode before this one (0 on the first step)

 private:
  struct Slot {
    std::string name;
    InfoType type;
    bool published;
    double number = 0;
    std::vector<int> list;
  };
  std::vector<Slot> slots_;
};

}  // namespace cradle::envs

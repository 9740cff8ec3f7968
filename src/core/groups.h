// Body-part groups shared by actuation (act_*), locks (lock_*) and touch (touch_*) config keys.
#pragma once

#include <array>
#include <optional>
#include <string_view>

namespace cradle {

enum class Group { kBody, kHead, kEyes, kArms, kHands, kFingers, kLegs, kFeet };

inline constexpr std::array<Group, 8> kAllGroups = {Group::kBody, Group::kHead,  Group::kEyes,
                                                    Group::kArms, Group::kHands, Group::kFingers,
                                                    Group::kLegs, Group::kFeet};

// Lower-case name as used in config keys: "body", "head", ..., "feet".
constexpr std::string_view group_name(Group group) {
  constexpr std::array<std::string_view, 8> kNames = {"body",  "head",    "eyes", "arms",
                                                      "hands", "fingers", "legs", "feet"};
  return kNames[static_cast<int>(group)];
}

constexpr std::optional<Group> group_from_name(std::string_view name) {
  for (Group g : kAllGroups) {
    if (group_name(g) == name) return g;
  }
  return std::nullopt;
}

// One flag per group, indexed by Group.
struct GroupFlags {
  std::array<bool, 8> flags{};
  constexpr bool operator[](Group g) const { return flags[static_cast<int>(g)]; }
  constexpr bool& operator[](Group g) { return flags[static_cast<int>(g)]; }
  static constexpr GroupFlags all(bool value) {
    GroupFlags f;
    f.flags.fill(value);
    return f;
  }
  friend constexpr bool operator==(const GroupFlags&, const GroupFlags&) = default;
};

}  // namespace cradle

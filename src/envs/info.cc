#include "envs/info.h"

#include <stdexcept>

namespace cradle::envs {

int Info::declare(std::string name, InfoType type, bool published) {
  if (find(name) >= 0) throw std::logic_error("info key '" + name + "' declared twice");
  slots_.push_back({.name = std::move(name), .type = type, .published = published});
  return size() - 1;
}

int Info::find(std::string_view name) const {
  for (int k = 0; k < size(); ++k) {
    if (slots_[k].name == name) return k;
  }
  return -1;
}

void Info::clear() {
  for (Slot& slot : slots_) {
    slot.number = 0;
    slot.list.clear();
  }
  steps = 0;
}

nlohmann::json Info::to_json() const {
  nlohmann::json j = nlohmann::json::object();
  for (const Slot& slot : slots_) {
    if (!slot.published) continue;
    // Each type keeps its JSON kind (integers stay integers, flags booleans).
    switch (slot.type) {
      case InfoType::kBool:
        j[slot.name] = slot.number != 0;
        break;
      case InfoType::kInt:
        j[slot.name] = static_cast<long>(slot.number);
        break;
      case InfoType::kReal:
        j[slot.name] = slot.number;
        break;
      case InfoType::kIntList:
        j[slot.name] = slot.list;
        break;
    }
  }
  j["steps"] = steps;
  return j;
}

}  // namespace cradle::envs

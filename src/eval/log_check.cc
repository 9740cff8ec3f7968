#include "eval/log_check.h"

#include "core/error.h"
#include "core/jsonl.h"

namespace cradle::eval {
namespace {

bool is_count(const nlohmann::json& value) {
  return value.is_number_integer() && value.get<long long>() >= 0;
}

}  // namespace

std::string entry_problem(const nlohmann::json& entry, Behavior behavior, int ngeom) {
  if (!entry.is_object()) return "expected an entry object, got " + std::string(entry.type_name());
  const auto steps = entry.find("steps");
  if (steps == entry.end() || !is_count(*steps)) {
    return "expected \"steps\" as an integer >= 0";
  }
  for (const char* key : {"score", "wall_time"}) {
    const auto it = entry.find(key);
    if (it != entry.end() && !it->is_number())
      return std::string("\"") + key + "\" is not a number";
  }
  if (behavior == Behavior::kSelfTouch) {
    for (const char* key : {"right_hand_touches", "left_hand_touches"}) {
      const auto it = entry.find(key);
      if (it == entry.end()) continue;
      if (!it->is_array()) return std::string("\"") + key + "\" is not a list of geom ids";
      for (const nlohmann::json& id : *it) {
        if (!is_count(id) || (ngeom >= 0 && id.get<long long>() >= ngeom)) {
          return std::string("\"") + key + "\" holds " + id.dump() +
                 (ngeom >= 0
                      ? ", not a geom id of this model (0 to " + std::to_string(ngeom - 1) + ")"
                      : ", not a geom id");
        }
      }
    }
  } else if (behavior == Behavior::kHandRegard) {
    const long long n = steps->get<long long>();
    for (const char* key :
         {"right_eye_right_hand", "right_eye_left_hand", "left_eye_right_hand",
          "left_eye_left_hand", "right_eye_either_hand", "left_eye_either_hand"}) {
      const auto it = entry.find(key);
      if (it == entry.end()) continue;
      if (!is_count(*it) || it->get<long long>() > n) {
        return std::string("\"") + key + "\" must be an integer from 0 to steps (" +
               std::to_string(n) + "), got " + it->dump();
      }
    }
  }
  return "";
}

std::vector<nlohmann::json> read_training_log(const std::filesystem::path& file, Behavior behavior,
                                              int ngeom) {
  return read_jsonl(
      file, [&](const nlohmann::json& entry) { return entry_problem(entry, behavior, ngeom); });
}

void check_training_entries(const std::vector<nlohmann::json>& entries, Behavior behavior,
                            int ngeom) {
  for (size_t i = 0; i < entries.size(); ++i) {
    const std::string problem = entry_problem(entries[i], behavior, ngeom);
    if (!problem.empty())
      throw UserError("training log entry " + std::to_string(i) + ": " + problem);
  }
}

}  // namespace cradle::eval

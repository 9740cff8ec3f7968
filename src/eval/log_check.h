// Training-log entries checked before they are scored: a line of logs/training.jsonl that is JSON
// but not an entry (42, null, a list, wrong types, geom ids the model does not have) is a
// one-line error naming the file and line, never a crash or an inflated score.
#pragma once

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/config.h"

namespace cradle::eval {

// What is wrong with one entry ("" when nothing): an object with an integer "steps" >= 0; for
// self-touch, "right_hand_touches" / "left_hand_touches" lists of geom ids in [0, ngeom) (any
// id >= 0 when ngeom < 0); for hand regard, the six counts integers in [0, steps]; "score" and
// "wall_time", when present, numbers.
std::string entry_problem(const nlohmann::json& entry, Behavior behavior, int ngeom);

// Every entry of a training.jsonl (read_jsonl's rules for blank and torn lines), each checked;
// UserError "<file>:<line>: <problem>".
std::vector<nlohmann::json> read_training_log(const std::filesystem::path& file, Behavior behavior,
                                              int ngeom = -1);

// The same check over entries already in memory (e.g. from Python); errors name the entry index.
void check_training_entries(const std::vector<nlohmann::json>& entries, Behavior behavior,
                            int ngeom = -1);

}  // namespace cradle::eval

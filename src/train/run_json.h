// A run's JSON files (run.json, latest.json, evaluation JSON, teacher.jsonl lines) read with every
// key's type checked: a missing file, a folder, bad JSON, a missing key or a value of another type
// is a one-line UserError naming the file (and line), the key and what was expected, never
// nlohmann's internal error and never a partial resume.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace cradle::train {

class RunJson {
 public:
  // Reads and parses `file`; its top level must be an object. `what` names the file for the
  // messages, e.g. "the run.json of a `cradle sami train` run".
  RunJson(std::filesystem::path file, const std::string& what);
  // A value already parsed (a JSON-lines entry, a nested object): `where` names it in messages
  // ("teacher.jsonl:12"); it must be an object.
  RunJson(std::string where, nlohmann::json value, const std::string& what);

  const std::string& where() const { return where_; }
  const nlohmann::json& json() const { return json_; }
  bool has(const char* key) const { return json_.contains(key); }

  std::string string(const char* key) const;
  std::uint64_t unsigned_integer(const char* key) const;                 // 0 to 2^64 - 1
  long count(const char* key) const;                                     // 0 to LONG_MAX
  long positive_integer(const char* key) const;                          // 1 to LONG_MAX
  double number(const char* key) const;                                  // finite
  bool boolean(const char* key) const;                                   // true or false
  std::vector<float> floats(const char* key) const;                      // [finite numbers]
  std::map<std::string, std::string> string_map(const char* key) const;  // {"name": "value"}
  // A nested object, named "<where>: <key>" in messages.
  RunJson object(const char* key) const;

 private:
  // The value of `key`; UserError naming `expected` when the key is missing.
  const nlohmann::json& at(const char* key, const char* expected) const;
  [[noreturn]] void wrong(const char* key, const char* expected) const;

  std::string where_;
  nlohmann::json json_;
};

}  // namespace cradle::train

// A SaMI run's JSON files (run.json, eval_<split>.json) read with every key's type checked: a
// missing file, a folder, bad JSON, a missing key or a value of another type is a one-line
// UserError naming the file, the key and what was expected (never nlohmann's internal error).
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

namespace cradle::train {

class SamiJson {
 public:
  // Reads and parses `file`; its top level must be an object. `what` names the file for the
  // messages, e.g. "the run.json of a `cradle sami train` run".
  SamiJson(std::filesystem::path file, const std::string& what);

  const std::filesystem::path& file() const { return file_; }
  const nlohmann::json& json() const { return json_; }

  std::string string(const char* key) const;
  std::uint64_t unsigned_integer(const char* key) const;                 // 0 to 2^64 - 1
  long positive_integer(const char* key) const;                          // 1 to LONG_MAX
  double number(const char* key) const;                                  // finite
  std::map<std::string, std::string> string_map(const char* key) const;  // {"name": "value"}

 private:
  // The value of `key`; UserError naming `expected` when the key is missing.
  const nlohmann::json& at(const char* key, const char* expected) const;
  [[noreturn]] void wrong(const char* key, const char* expected) const;

  std::filesystem::path file_;
  nlohmann::json json_;
};

}  // namespace cradle::train

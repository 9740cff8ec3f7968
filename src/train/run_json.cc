#include "train/run_json.h"

#include <climits>
#include <cmath>
#include <fstream>
#include <system_error>

#include "core/error.h"

namespace cradle::train {

RunJson::RunJson(std::filesystem::path file, const std::string& what) : where_(file.string()) {
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(file, ec);
  if (!std::filesystem::exists(status)) {
    throw UserError(where_ + " does not exist; expected " + what);
  }
  if (!std::filesystem::is_regular_file(status)) {
    throw UserError(where_ + " is " +
                    (std::filesystem::is_directory(status) ? "a folder" : "not a regular file") +
                    "; expected " + what);
  }
  std::ifstream in(file);
  if (!in) throw UserError("cannot read " + where_ + "; expected " + what);
  try {
    json_ = nlohmann::json::parse(in);
  } catch (const std::exception&) {
    throw UserError(where_ + " is not valid JSON (cut short or edited?); expected " + what);
  }
  if (!json_.is_object()) throw UserError(where_ + " is not a JSON object; expected " + what);
}

RunJson::RunJson(std::string where, nlohmann::json value, const std::string& what)
    : where_(std::move(where)), json_(std::move(value)) {
  if (!json_.is_object()) throw UserError(where_ + " is not a JSON object; expected " + what);
}

const nlohmann::json& RunJson::at(const char* key, const char* expected) const {
  const auto it = json_.find(key);
  if (it == json_.end()) {
    throw UserError(where_ + " has no key \"" + key + "\"; expected " + expected);
  }
  return *it;
}

void RunJson::wrong(const char* key, const char* expected) const {
  std::string value = json_.at(key).dump();
  if (value.size() > 40) value = value.substr(0, 37) + "...";
  throw UserError(where_ + ": \"" + key + "\" is " + value + "; expected " + expected);
}

std::string RunJson::string(const char* key) const {
  const char* expected = "a string";
  const nlohmann::json& v = at(key, expected);
  if (!v.is_string()) wrong(key, expected);
  return v.get<std::string>();
}

std::uint64_t RunJson::unsigned_integer(const char* key) const {
  const char* expected = "an integer from 0 to 18446744073709551615";
  const nlohmann::json& v = at(key, expected);
  // A non-negative integer parses as number_unsigned; -1 and 1.5 do not.
  if (!v.is_number_unsigned()) wrong(key, expected);
  return v.get<std::uint64_t>();
}

long RunJson::count(const char* key) const {
  const char* expected = "an integer >= 0";
  const nlohmann::json& v = at(key, expected);
  if (!v.is_number_unsigned() || v.get<std::uint64_t>() > static_cast<std::uint64_t>(LONG_MAX)) {
    wrong(key, expected);
  }
  return static_cast<long>(v.get<std::uint64_t>());
}

long RunJson::positive_integer(const char* key) const {
  const char* expected = "a positive integer";
  const nlohmann::json& v = at(key, expected);
  if (!v.is_number_unsigned() || v.get<std::uint64_t>() == 0 ||
      v.get<std::uint64_t>() > static_cast<std::uint64_t>(LONG_MAX)) {
    wrong(key, expected);
  }
  return static_cast<long>(v.get<std::uint64_t>());
}

double RunJson::number(const char* key) const {
  const char* expected = "a number";
  const nlohmann::json& v = at(key, expected);
  if (!v.is_number() || !std::isfinite(v.get<double>())) wrong(key, expected);
  return v.get<double>();
}

bool RunJson::boolean(const char* key) const {
  const char* expected = "true or false";
  const nlohmann::json& v = at(key, expected);
  if (!v.is_boolean()) wrong(key, expected);
  return v.get<bool>();
}

std::vector<float> RunJson::floats(const char* key) const {
  const char* expected = "a list of numbers";
  const nlohmann::json& v = at(key, expected);
  if (!v.is_array()) wrong(key, expected);
  std::vector<float> out;
  for (const nlohmann::json& x : v) {
    if (!x.is_number() || !std::isfinite(x.get<double>())) wrong(key, expected);
    out.push_back(x.get<float>());
  }
  return out;
}

std::map<std::string, std::string> RunJson::string_map(const char* key) const {
  const char* expected = "an object of \"name\": \"value\" strings";
  const nlohmann::json& v = at(key, expected);
  if (!v.is_object()) wrong(key, expected);
  std::map<std::string, std::string> out;
  for (const auto& [name, value] : v.items()) {
    if (!value.is_string()) wrong(key, expected);
    out[name] = value.get<std::string>();
  }
  return out;
}

RunJson RunJson::object(const char* key) const {
  const char* expected = "an object";
  const nlohmann::json& v = at(key, expected);
  if (!v.is_object()) wrong(key, expected);
  return RunJson(where_ + ": " + key, v, expected);
}

}  // namespace cradle::train

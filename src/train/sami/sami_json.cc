#include "train/sami/sami_json.h"

#include <climits>
#include <cmath>
#include <fstream>
#include <system_error>

#include "core/error.h"

namespace cradle::train {

SamiJson::SamiJson(std::filesystem::path file, const std::string& what) : file_(std::move(file)) {
  const std::string name = file_.string();
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(file_, ec);
  if (!std::filesystem::exists(status)) {
    throw UserError(name + " does not exist; expected " + what);
  }
  if (!std::filesystem::is_regular_file(status)) {
    throw UserError(name + " is " +
                    (std::filesystem::is_directory(status) ? "a folder" : "not a regular file") +
                    "; expected " + what);
  }
  std::ifstream in(file_);
  if (!in) throw UserError("cannot read " + name + "; expected " + what);
  try {
    json_ = nlohmann::json::parse(in);
  } catch (const std::exception&) {
    throw UserError(name + " is not valid JSON (cut short or edited?); expected " + what);
  }
  if (!json_.is_object()) throw UserError(name + " is not a JSON object; expected " + what);
}

const nlohmann::json& SamiJson::at(const char* key, const char* expected) const {
  const auto it = json_.find(key);
  if (it == json_.end()) {
    throw UserError(file_.string() + " has no key \"" + key + "\"; expected " + expected);
  }
  return *it;
}

void SamiJson::wrong(const char* key, const char* expected) const {
  std::string value = json_.at(key).dump();
  if (value.size() > 40) value = value.substr(0, 37) + "...";
  throw UserError(file_.string() + ": \"" + key + "\" is " + value + "; expected " + expected);
}

std::string SamiJson::string(const char* key) const {
  const char* expected = "a string";
  const nlohmann::json& v = at(key, expected);
  if (!v.is_string()) wrong(key, expected);
  return v.get<std::string>();
}

std::uint64_t SamiJson::unsigned_integer(const char* key) const {
  const char* expected = "an integer from 0 to 18446744073709551615";
  const nlohmann::json& v = at(key, expected);
  // A non-negative integer parses as number_unsigned; -1 and 1.5 do not.
  if (!v.is_number_unsigned()) wrong(key, expected);
  return v.get<std::uint64_t>();
}

long SamiJson::positive_integer(const char* key) const {
  const char* expected = "a positive integer";
  const nlohmann::json& v = at(key, expected);
  if (!v.is_number_unsigned() || v.get<std::uint64_t>() == 0 ||
      v.get<std::uint64_t>() > static_cast<std::uint64_t>(LONG_MAX)) {
    wrong(key, expected);
  }
  return static_cast<long>(v.get<std::uint64_t>());
}

double SamiJson::number(const char* key) const {
  const char* expected = "a number";
  const nlohmann::json& v = at(key, expected);
  if (!v.is_number() || !std::isfinite(v.get<double>())) wrong(key, expected);
  return v.get<double>();
}

std::map<std::string, std::string> SamiJson::string_map(const char* key) const {
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

}  // namespace cradle::train

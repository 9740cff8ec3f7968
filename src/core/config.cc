// Strict YAML reading and writing of Config. One table (for_each_field) lists every key with its
// field and limits; parsing, YAML output, JSON output and the key list all walk that table.
#include "core/config.h"

#include <fcntl.h>
#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <limits>
#include <map>
#include <sstream>
#include <system_error>
#include <type_traits>
#include <vector>

#include "core/error.h"

namespace cradle {
namespace {

// One accepted spelling of an enum value.
template <typename E>
struct NameEntry {
  std::string_view name;
  E value;
};

// Name tables per enum: the first `kCanonical` entries are the canonical names (one per value, in
// enum order); any further entries are accepted aliases.
template <typename E>
struct EnumNames;

template <>
struct EnumNames<Behavior> {
  static constexpr std::array<NameEntry<Behavior>, 5> kAll = {
      {{"none", Behavior::kNone},
       {"self_touch", Behavior::kSelfTouch},
       {"hand_regard", Behavior::kHandRegard},
       {"selftouch", Behavior::kSelfTouch},
       {"handregard", Behavior::kHandRegard}}};
  static constexpr size_t kCanonical = 3;
};

template <>
struct EnumNames<SceneKind> {
  static constexpr std::array<NameEntry<SceneKind>, 3> kAll = {
      {{"base", SceneKind::kBase}, {"crib", SceneKind::kCrib}, {"cubes", SceneKind::kCubes}}};
  static constexpr size_t kCanonical = 3;
};

template <>
struct EnumNames<ActuationModel> {
  static constexpr std::array<NameEntry<ActuationModel>, 3> kAll = {
      {{"spring_damper", ActuationModel::kSpringDamper},
       {"muscle", ActuationModel::kMuscle},
       {"positional", ActuationModel::kPositional}}};
  static constexpr size_t kCanonical = 3;
};

template <>
struct EnumNames<TouchFunction> {
  static constexpr std::array<NameEntry<TouchFunction>, 3> kAll = {
      {{"normal", TouchFunction::kNormal},
       {"force_vector", TouchFunction::kForceVector},
       {"force_vector_global", TouchFunction::kForceVectorGlobal}}};
  static constexpr size_t kCanonical = 3;
};

template <>
struct EnumNames<TouchResponse> {
  static constexpr std::array<NameEntry<TouchResponse>, 2> kAll = {
      {{"nearest", TouchResponse::kNearest}, {"spread_linear", TouchResponse::kSpreadLinear}}};
  static constexpr size_t kCanonical = 2;
};

// Canonical name of an enum value.
template <typename E>
constexpr std::string_view canonical_name(E value) {
  return EnumNames<E>::kAll[static_cast<size_t>(value)].name;
}

// Enum value for any accepted spelling.
template <typename E>
constexpr std::optional<E> enum_from_name(std::string_view name) {
  for (const auto& entry : EnumNames<E>::kAll) {
    if (entry.name == name) return entry.value;
  }
  return std::nullopt;
}

// "a, b, c" from the canonical names, plus any aliases in parentheses, for error messages.
template <typename E>
std::string enum_options() {
  const auto& all = EnumNames<E>::kAll;
  std::string text;
  for (size_t i = 0; i < EnumNames<E>::kCanonical; ++i) {
    if (i > 0) text += ", ";
    text += all[i].name;
  }
  if (all.size() > EnumNames<E>::kCanonical) {
    text += " (also accepted: ";
    for (size_t i = EnumNames<E>::kCanonical; i < all.size(); ++i) {
      if (i > EnumNames<E>::kCanonical) text += ", ";
      text += all[i].name;
    }
    text += ")";
  }
  return text;
}

// The order the API page and the reference YAMLs list the per-group keys in.
constexpr std::array<Group, 8> kDocGroupOrder = {Group::kHands, Group::kFingers, Group::kArms,
                                                 Group::kFeet,  Group::kLegs,    Group::kBody,
                                                 Group::kHead,  Group::kEyes};

// Allowed interval for a numeric key; unbounded by default.
struct Range {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false;  // true: lo itself is excluded
};

constexpr double kIntMax = std::numeric_limits<int>::max();
constexpr Range kAny{};
constexpr Range kPositiveInt{1.0, kIntMax};
constexpr double kMinTouchScale = 0.25;              // ~16 x the reference skin's 17,049 sensors
constexpr std::uintmax_t kMaxConfigBytes = 1 << 20;  // configs are a few KiB

// Calls visit(key, field, range) for every key, in to_yaml order. C is Config or const Config.
template <typename C, typename Visit>
void for_each_field(C& c, Visit&& visit) {
  visit("save_dir", c.save_dir, kAny);
  visit("behavior", c.behavior, kAny);
  visit("scene", c.scene, kAny);
  visit("max_episode_steps", c.max_episode_steps, kPositiveInt);
  // At most 100 physics steps per env step (beyond that an env step runs for seconds).
  visit("frame_skip", c.frame_skip, Range{1.0, 100.0});
  visit("render_size", c.render_size, Range{16.0, 4096.0});
  visit("save_logs_every", c.save_logs_every, kPositiveInt);
  visit("proprio_velocity", c.proprio_velocity, kAny);
  visit("proprio_torque", c.proprio_torque, kAny);
  visit("proprio_limits", c.proprio_limits, kAny);
  visit("proprio_actuation", c.proprio_actuation, kAny);
  visit("vestibular_active", c.vestibular_active, kAny);
  visit("vision_active", c.vision_active, kAny);
  visit("vision_resolution", c.vision_resolution, Range{1.0, 1024.0});
  visit("touch_active", c.touch_active, kAny);
  // 0 turns touch off; with touch on, parse_config also bounds it (kMinTouchScale..100).
  visit("touch_scale", c.touch_scale, Range{0.0});
  visit("touch_function", c.touch_function, kAny);
  visit("touch_response", c.touch_response, kAny);
  for (Group g : kDocGroupOrder) {
    visit("touch_" + std::string(group_name(g)), c.touch_groups.flags[static_cast<size_t>(g)],
          kAny);
  }
  visit("actuation_model", c.actuation_model, kAny);
  for (Group g : kDocGroupOrder) {
    visit("act_" + std::string(group_name(g)), c.act_groups.flags[static_cast<size_t>(g)], kAny);
  }
  for (Group g : kDocGroupOrder) {
    visit("lock_" + std::string(group_name(g)), c.lock_groups.flags[static_cast<size_t>(g)], kAny);
  }
  visit("hand_regard_half_angle", c.hand_regard_half_angle, Range{0.0, 90.0, true});
  visit("hand_regard_occlusion", c.hand_regard_occlusion, kAny);
  visit("mattress_friction_applies", c.mattress_friction_applies, kAny);
}

// First key written by the Cradle extensions; to_yaml puts a comment line before it.
constexpr std::string_view kFirstExtensionKey = "hand_regard_half_angle";

// Throws a UserError whose message is forced onto one line.
[[noreturn]] void fail(std::string message) {
  for (char& ch : message) {
    if (ch == '\n' || ch == '\r') ch = ' ';
  }
  throw UserError(message);
}

// Shortest decimal text that reads back to the same double ("1", "0.25", "1e-07").
std::string shortest_number(double value) {
  std::array<char, 64> buffer{};
  auto result = std::to_chars(buffer.data(), buffer.data() + buffer.size(), value);
  return std::string(buffer.data(), result.ptr);
}

// Scalar text made printable and short for an error message.
std::string clip(std::string_view text) {
  constexpr size_t kMax = 40;
  std::string out;
  for (char ch : text.substr(0, kMax)) {
    if (ch == '\n') {
      out += "\\n";
    } else if (static_cast<unsigned char>(ch) < 0x20) {
      out += ' ';
    } else {
      out += ch;
    }
  }
  if (text.size() > kMax) out += "...";
  return out;
}

// True for a scalar the YAML author wrote as a string: quoted or tagged !!str.
bool is_quoted(const YAML::Node& node) {
  return node.Tag() == "!" || node.Tag() == "tag:yaml.org,2002:str";
}

// What a value node holds, for "got ..." in messages.
std::string describe(const YAML::Node& node) {
  if (node.IsSequence()) return "a list";
  if (node.IsMap()) return "a mapping";
  if (node.IsNull() || !node.IsDefined()) return "nothing";
  if (is_quoted(node)) return "\"" + clip(node.Scalar()) + "\" (a quoted string)";
  return "'" + clip(node.Scalar()) + "'";
}

// The key being read and the file it came from.
struct Site {
  std::string_view source;
  std::string_view key;
};

// "<source>: key '<key>' " — the start of every value error.
std::string key_prefix(const Site& site) {
  return std::string(site.source) + ": key '" + std::string(site.key) + "' ";
}

// Rejects null, list and mapping values; `expected` says what the key needs.
const std::string& scalar_text(const Site& site, const YAML::Node& node,
                               std::string_view expected) {
  if (node.IsNull() || !node.IsDefined()) {
    fail(key_prefix(site) + "has no value; expected " + std::string(expected));
  }
  if (!node.IsScalar()) {
    fail(key_prefix(site) + "must be " + std::string(expected) + ", got " + describe(node));
  }
  return node.Scalar();
}

// Lower-case copy (ASCII).
std::string lower(std::string_view text) {
  std::string out(text);
  for (char& ch : out) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return out;
}

// Human wording of a range, e.g. "at least 1", "between 16 and 4096".
std::string range_text(const Range& range) {
  const bool has_lo = std::isfinite(range.lo);
  const bool has_hi = std::isfinite(range.hi) && range.hi < kIntMax;
  const std::string lo = shortest_number(range.lo);
  const std::string hi = shortest_number(range.hi);
  if (has_lo && has_hi) {
    return range.lo_open ? "greater than " + lo + " and at most " + hi
                         : "between " + lo + " and " + hi;
  }
  if (has_lo) return (range.lo_open ? "greater than " : "at least ") + lo;
  if (has_hi) return "at most " + hi;
  return "any number";
}

// Fails when value lies outside range.
void check_range(const Site& site, double value, const Range& range, std::string_view given) {
  const bool below = range.lo_open ? value <= range.lo : value < range.lo;
  if (below || value > range.hi) {
    fail(key_prefix(site) + "must be " + range_text(range) + ", got " + std::string(given));
  }
}

// Bool keys: real YAML booleans only (true/false/yes/no/on/off, any capitalisation).
void read_into(const Site& site, const YAML::Node& node, const Range&, bool& out) {
  constexpr std::string_view kExpected = "a boolean (True or False)";
  const std::string& text = scalar_text(site, node, kExpected);
  const std::string word = lower(text);
  if (!is_quoted(node)) {
    if (word == "true" || word == "yes" || word == "on") {
      out = true;
      return;
    }
    if (word == "false" || word == "no" || word == "off") {
      out = false;
      return;
    }
  }
  fail(key_prefix(site) + "must be " + std::string(kExpected) + ", got " + describe(node));
}

// Int keys: an unquoted decimal integer (optional sign) inside the key's range.
void read_into(const Site& site, const YAML::Node& node, const Range& range, int& out) {
  constexpr std::string_view kExpected = "an integer";
  const std::string& text = scalar_text(site, node, kExpected);
  std::string_view digits = text;
  if (!digits.empty() && digits.front() == '+') digits.remove_prefix(1);
  long long value = 0;
  const auto result = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  const bool whole = result.ec == std::errc() && result.ptr == digits.data() + digits.size();
  if (is_quoted(node) || digits.empty() || digits.front() == '+' || text.starts_with("+-") ||
      (result.ec != std::errc::result_out_of_range && !whole)) {
    fail(key_prefix(site) + "must be " + std::string(kExpected) + ", got " + describe(node));
  }
  if (result.ec == std::errc::result_out_of_range || value > std::numeric_limits<int>::max() ||
      value < std::numeric_limits<int>::min()) {
    fail(key_prefix(site) + "must be " + range_text(range) + " and fit in 32 bits, got " +
         clip(text));
  }
  check_range(site, static_cast<double>(value), range, clip(text));
  out = static_cast<int>(value);
}

// Float keys: an unquoted finite number (integers allowed, "1." allowed) inside the range.
void read_into(const Site& site, const YAML::Node& node, const Range& range, double& out) {
  constexpr std::string_view kExpected = "a number";
  const std::string& text = scalar_text(site, node, kExpected);
  const std::string word = lower(text);
  if (!is_quoted(node) &&
      (word == ".inf" || word == "+.inf" || word == "-.inf" || word == ".nan")) {
    fail(key_prefix(site) + "must be a finite number, got " + describe(node));
  }
  std::string_view body = text;
  if (!body.empty() && body.front() == '+' && !text.starts_with("+-")) body.remove_prefix(1);
  const size_t start = !body.empty() && body.front() == '-' ? 1 : 0;
  const bool starts_ok =
      body.size() > start &&
      (std::isdigit(static_cast<unsigned char>(body[start])) || body[start] == '.');
  double value = 0.0;
  const auto result = std::from_chars(body.data(), body.data() + body.size(), value);
  const bool consumed = result.ptr == body.data() + body.size();
  if (!is_quoted(node) && starts_ok && consumed && result.ec == std::errc::result_out_of_range) {
    fail(key_prefix(site) + "must be a finite number within double range, got " + describe(node));
  }
  if (is_quoted(node) || !starts_ok || !consumed || result.ec != std::errc()) {
    fail(key_prefix(site) + "must be " + std::string(kExpected) + ", got " + describe(node));
  }
  if (!std::isfinite(value)) {
    fail(key_prefix(site) + "must be a finite number, got " + describe(node));
  }
  check_range(site, value, range, clip(text));
  out = value + 0.0;  // turns -0 into +0
}

// String keys (save_dir): any non-empty scalar.
void read_into(const Site& site, const YAML::Node& node, const Range&, std::string& out) {
  constexpr std::string_view kExpected = "a non-empty path";
  const std::string& text = scalar_text(site, node, kExpected);
  if (text.empty()) fail(key_prefix(site) + "must be " + std::string(kExpected) + ", got ''");
  out = text;
}

// Enum keys: one of the accepted names, exactly.
template <typename E>
requires std::is_enum_v<E>
void read_into(const Site& site, const YAML::Node& node, const Range&, E& out) {
  const std::string expected = "one of " + enum_options<E>();
  const std::string& text = scalar_text(site, node, expected);
  if (auto value = enum_from_name<E>(text)) {
    out = *value;
    return;
  }
  fail(key_prefix(site) + "must be " + expected + "; got " + describe(node));
}

// Reads one YAML value into the Config field it is bound to.
using Reader = std::function<void(const Site&, const YAML::Node&)>;

// Key -> reader writing into `config`.
std::map<std::string, Reader, std::less<>> make_readers(Config& config) {
  std::map<std::string, Reader, std::less<>> readers;
  for_each_field(config, [&readers](const std::string& key, auto& field, const Range& range) {
    readers.emplace(key, [&field, range](const Site& site, const YAML::Node& node) {
      read_into(site, node, range, field);
    });
  });
  return readers;
}

// Classic edit distance (insert, delete, substitute), case-insensitive.
size_t edit_distance(std::string_view a, std::string_view b) {
  const std::string x = lower(a);
  const std::string y = lower(b);
  std::vector<size_t> row(y.size() + 1);
  for (size_t j = 0; j <= y.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= x.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= y.size(); ++j) {
      const size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (x[i - 1] == y[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[y.size()];
}

// Closest valid key to a misspelt one: nearest by edit distance when close enough, else the one
// key containing it (e.g. "resolution"); empty when nothing fits.
std::string suggest_key(std::string_view key) {
  const auto keys = config_keys();
  std::string best;
  size_t best_distance = std::max<size_t>(2, key.size() / 4) + 1;
  for (const std::string& candidate : keys) {
    const size_t distance = edit_distance(key, candidate);
    if (distance < best_distance) {
      best_distance = distance;
      best = candidate;
    }
  }
  if (!best.empty() || key.size() < 4) return best;
  const std::string needle = lower(key);
  std::vector<std::string> containing;
  for (const std::string& candidate : keys) {
    if (candidate.find(needle) != std::string::npos) containing.push_back(candidate);
  }
  return containing.size() == 1 ? containing.front() : std::string();
}

// YAML text for one value, in the reference kit's style.
std::string yaml_value(bool value) { return value ? "True" : "False"; }
std::string yaml_value(int value) { return std::to_string(value); }

std::string yaml_value(double value) {
  if (std::isnan(value)) return ".nan";
  if (std::isinf(value)) return value > 0 ? ".inf" : "-.inf";
  // Always with a '.', so that PyYAML also reads it as a float ("1.0", "1.0e-07").
  std::string text = shortest_number(value);
  if (text.find('.') == std::string::npos) text.insert(std::min(text.find('e'), text.size()), ".0");
  return text;
}

template <typename E>
requires std::is_enum_v<E> std::string yaml_value(E value) {
  return std::string(canonical_name(value));
}

// Strings stay plain when YAML would read them back as the same string, else double-quoted.
std::string yaml_value(const std::string& value) {
  static constexpr std::array<std::string_view, 9> kReserved = {"true", "false", "yes", "no", "on",
                                                                "off",  "null",  "y",   "n"};
  const auto safe_char = [](char ch) {
    return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '/' || ch == '.' ||
           ch == '-' || ch == '+';
  };
  const bool plain = !value.empty() &&
                     (std::isalpha(static_cast<unsigned char>(value.front())) ||
                      value.front() == '_' || value.front() == '/') &&
                     std::all_of(value.begin(), value.end(), safe_char) &&
                     std::find(kReserved.begin(), kReserved.end(), lower(value)) == kReserved.end();
  if (plain) return value;
  std::string out = "\"";
  for (char ch : value) {
    const auto byte = static_cast<unsigned char>(ch);
    if (ch == '"' || ch == '\\') {
      out += '\\';
      out += ch;
    } else if (ch == '\n') {
      out += "\\n";
    } else if (ch == '\t') {
      out += "\\t";
    } else if (byte < 0x20 || byte == 0x7f) {
      constexpr std::string_view kHex = "0123456789abcdef";
      out += "\\x";
      out += kHex[byte >> 4];
      out += kHex[byte & 0xf];
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

// JSON value for one field; enums as names.
template <typename T>
nlohmann::json json_value(const T& value) {
  if constexpr (std::is_enum_v<T>) {
    return std::string(canonical_name(value));
  } else {
    return value;
  }
}

// Parses all YAML documents in text; syntax errors become one-line UserErrors with the position.
std::vector<YAML::Node> load_documents(std::string_view text, std::string_view source) {
  try {
    return YAML::LoadAll(std::string(text));
  } catch (const YAML::ParserException& e) {
    fail(std::string(source) + ": YAML syntax error at line " + std::to_string(e.mark.line + 1) +
         ", column " + std::to_string(e.mark.column + 1) + ": " + e.msg);
  } catch (const YAML::Exception& e) {
    fail(std::string(source) + ": YAML error: " + e.msg);
  }
}

}  // namespace

Config default_config() { return Config{}; }

Config parse_config(std::string_view yaml_text, std::string_view source) {
  const std::vector<YAML::Node> documents = load_documents(yaml_text, source);
  Config config;
  // An empty file (or one holding only comments) sets nothing.
  if (documents.empty()) return config;
  if (documents.size() > 1) {
    fail(std::string(source) + ": expected a single YAML document, found " +
         std::to_string(documents.size()) + " (separated by '---')");
  }
  const YAML::Node& root = documents.front();
  if (root.IsNull()) return config;
  if (!root.IsMap()) {
    fail(std::string(source) + ": top level must be a mapping of 'key: value' lines, got " +
         describe(root));
  }
  const auto readers = make_readers(config);
  std::map<std::string, int, std::less<>> seen_lines;
  // Keys in file order, so the first problem in the file is the one reported.
  for (const auto& item : root) {
    const YAML::Node& key_node = item.first;
    if (!key_node.IsScalar()) {
      fail(std::string(source) + ": every key must be a plain name, got " + describe(key_node));
    }
    const std::string& key = key_node.Scalar();
    const auto reader = readers.find(key);
    if (reader == readers.end()) {
      const std::string suggestion = suggest_key(key);
      fail(std::string(source) + ": unknown key '" + clip(key) + "'" +
           (suggestion.empty() ? std::string(" (not a BabyBench or Cradle config key)")
                               : "; did you mean '" + suggestion + "'?"));
    }
    const int line = key_node.Mark().line + 1;
    const auto [previous, inserted] = seen_lines.emplace(key, line);
    if (!inserted) {
      fail(std::string(source) + ": key '" + key + "' is set twice (lines " +
           std::to_string(previous->second) + " and " + std::to_string(line) + ")");
    }
    reader->second(Site{source, key}, item.second);
  }
  // Keys that only make sense together.
  // The skin has ~1 / touch_scale^2 sensors: below kMinTouchScale it outgrows memory and time.
  if (config.touch_active && config.touch_scale > 0 &&
      (config.touch_scale < kMinTouchScale || config.touch_scale > 100)) {
    fail(std::string(source) + ": key 'touch_scale' must be 0 (touch off) or between " +
         shortest_number(kMinTouchScale) + " and 100 when touch_active is True, got " +
         shortest_number(config.touch_scale));
  }
  bool actuated = false;
  for (const bool on : config.act_groups.flags) actuated = actuated || on;
  if (!actuated) {
    fail(std::string(source) +
         ": no actuated joints: every act_* key is False; set at least one to True");
  }
  return config;
}

Config load_config(const std::filesystem::path& file) {
  const std::string source = file.string();
  std::error_code status_error;
  const auto status = std::filesystem::status(file, status_error);
  if (!std::filesystem::exists(status)) {
    fail(source + ": cannot read config file: no such file");
  }
  if (std::filesystem::is_directory(status)) {
    fail(source + ": cannot read config file: it is a directory");
  }
  // Devices (/dev/zero) could feed bytes forever: the size is capped.
  // POSIX reads, so a failing read (e.g. /proc/self/mem, EIO) is an error, not an empty file.
  const int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    fail(source + ": cannot read config file: " + std::generic_category().message(errno));
  }
  std::string text;
  char buffer[65536];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int error = errno;
      ::close(fd);
      fail(source + ": cannot read config file: " + std::generic_category().message(error));
    }
    if (n == 0) break;
    text.append(buffer, static_cast<size_t>(n));
    if (text.size() > kMaxConfigBytes) {
      ::close(fd);
      fail(source + ": cannot read config file: larger than " +
           std::to_string(kMaxConfigBytes >> 10) + " KiB");
    }
  }
  ::close(fd);
  return parse_config(text, source);
}

std::string to_yaml(const Config& config) {
  std::string out;
  for_each_field(config, [&out](const std::string& key, const auto& field, const Range&) {
    if (key == kFirstExtensionKey) out += "# Cradle extensions (not read by the reference kit)\n";
    out += key + ": " + yaml_value(field) + "\n";
  });
  return out;
}

nlohmann::json to_json(const Config& config) {
  nlohmann::json out = nlohmann::json::object();
  for_each_field(config, [&out](const std::string& key, const auto& field, const Range&) {
    out[key] = json_value(field);
  });
  return out;
}

std::span<const std::string> config_keys() {
  // Built once from the field table; never modified afterwards.
  static const std::vector<std::string> kKeys = [] {
    std::vector<std::string> keys;
    const Config config;
    for_each_field(config, [&keys](const std::string& key, const auto&, const Range&) {
      keys.push_back(key);
    });
    return keys;
  }();
  return kKeys;
}

std::string_view behavior_name(Behavior behavior) { return canonical_name(behavior); }
std::string_view scene_name(SceneKind scene) { return canonical_name(scene); }
std::string_view actuation_model_name(ActuationModel model) { return canonical_name(model); }
std::string_view touch_function_name(TouchFunction function) { return canonical_name(function); }
std::string_view touch_response_name(TouchResponse response) { return canonical_name(response); }

std::optional<Behavior> behavior_from_name(std::string_view name) {
  return enum_from_name<Behavior>(name);
}
std::optional<SceneKind> scene_from_name(std::string_view name) {
  return enum_from_name<SceneKind>(name);
}
std::optional<ActuationModel> actuation_model_from_name(std::string_view name) {
  return enum_from_name<ActuationModel>(name);
}
std::optional<TouchFunction> touch_function_from_name(std::string_view name) {
  return enum_from_name<TouchFunction>(name);
}
std::optional<TouchResponse> touch_response_from_name(std::string_view name) {
  return enum_from_name<TouchResponse>(name);
}

}  // namespace cradle

namespace cradle {

Config test_installation_config() {
  Config c;
  c.save_dir = "results/test_installation";
  c.touch_function = TouchFunction::kForceVector;
  c.touch_response = TouchResponse::kSpreadLinear;
  c.lock_groups[Group::kFeet] = true;
  return c;
}

}  // namespace cradle

#include "learn/hyperparams.h"

#include <charconv>
#include <sstream>
#include <system_error>
#include <type_traits>

#include "core/error.h"
#include "learn/hyperparam_ranges.h"

namespace cradle::learn {
namespace {

std::string_view trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t\r");
  if (first == std::string_view::npos) return {};
  const auto last = s.find_last_not_of(" \t\r");
  return s.substr(first, last - first + 1);
}

// Leaves `value` unchanged unless the whole text is a number.
template <typename T>
bool parse_number(std::string_view text, T& value) {
  text = trim(text);
  T parsed{};
  const auto result = std::from_chars(text.data(), text.data() + text.size(), parsed);
  if (text.empty() || result.ec != std::errc() || result.ptr != text.data() + text.size()) {
    return false;
  }
  value = parsed;
  return true;
}

bool parse_value(std::string_view text, int* field) { return parse_number(text, *field); }
bool parse_value(std::string_view text, long* field) { return parse_number(text, *field); }
bool parse_value(std::string_view text, double* field) { return parse_number(text, *field); }
bool parse_value(std::string_view text, bool* field) {
  text = trim(text);
  if (text == "true" || text == "True" || text == "1") {
    *field = true;
  } else if (text == "false" || text == "False" || text == "0") {
    *field = false;
  } else {
    return false;
  }
  return true;
}
bool parse_value(std::string_view text, std::string* field) {
  *field = std::string(trim(text));
  return true;
}
bool parse_value(std::string_view text, std::vector<int>* field) {
  // "" is the empty list; otherwise every comma separates two numbers ("64," and ",64" do not
  // parse: a list cut short is a typo, not a shorter network).
  std::vector<int> values;
  text = trim(text);
  while (!text.empty()) {
    const auto comma = text.find(',');
    int value = 0;
    if (!parse_number(text.substr(0, comma), value)) return false;
    values.push_back(value);
    if (comma == std::string_view::npos) break;
    text = text.substr(comma + 1);
    if (trim(text).empty()) return false;
  }
  *field = std::move(values);
  return true;
}

std::string format_value(const int* field) { return std::to_string(*field); }
std::string format_value(const long* field) { return std::to_string(*field); }
std::string format_value(const double* field) {
  // Shortest text that reads back to the same double.
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), *field);
  return std::string(buffer, result.ptr);
}
std::string format_value(const bool* field) { return *field ? "true" : "false"; }
std::string format_value(const std::string* field) { return *field; }
std::string format_value(const std::vector<int>* field) {
  std::string text;
  for (size_t i = 0; i < field->size(); ++i) {
    if (i > 0) text += ",";
    text += std::to_string((*field)[i]);
  }
  return text;
}

}  // namespace

void Hyperparameters::add(std::string name, Field field, std::string doc) {
  entries_.push_back({std::move(name), field, std::move(doc)});
}

bool Hyperparameters::contains(std::string_view name) const {
  for (const Entry& entry : entries_) {
    if (entry.name == name) return true;
  }
  return false;
}

void Hyperparameters::apply(const std::map<std::string, std::string>& overrides) {
  for (const auto& [name, text] : overrides) {
    const Entry* found = nullptr;
    for (const Entry& entry : entries_) {
      if (entry.name == name) found = &entry;
    }
    if (found == nullptr) {
      std::string known;
      for (const Entry& entry : entries_) known += (known.empty() ? "" : ", ") + entry.name;
      throw UserError("unknown hyperparameter '" + name + "' (known: " + known + ")");
    }
    const bool ok = std::visit([&](auto* field) { return parse_value(text, field); }, found->field);
    if (!ok) throw UserError("hyperparameter '" + name + "': cannot parse '" + text + "'");
    // Numbers must lie in their declared range (learn/hyperparam_ranges.h).
    std::visit(
        [&](const auto* field) {
          using T = std::remove_cvref_t<decltype(*field)>;
          if constexpr (std::is_same_v<T, int> || std::is_same_v<T, long> ||
                        std::is_same_v<T, double>) {
            check_hyperparameter_range(name, static_cast<double>(*field));
          } else if constexpr (std::is_same_v<T, std::vector<int>>) {
            for (const int v : *field) check_hyperparameter_range(name, v);
          }
        },
        found->field);
  }
}

std::string Hyperparameters::to_text() const {
  std::string text;
  for (const Entry& entry : entries_) {
    text += entry.name + " = " +
            std::visit([](const auto* field) { return format_value(field); }, entry.field) + "\n";
  }
  return text;
}

std::string Hyperparameters::describe() const {
  std::string text;
  for (const Entry& entry : entries_) {
    text += entry.name + " (" +
            std::visit([](const auto* field) { return format_value(field); }, entry.field) +
            "): " + entry.doc + "\n";
  }
  return text;
}

std::map<std::string, std::string> parse_hyperparameter_flags(
    const std::vector<std::string>& flags) {
  std::map<std::string, std::string> out;
  for (const std::string& kv : flags) {
    const size_t eq = kv.find('=');
    if (eq == std::string::npos || eq == 0) {
      throw UserError("--hp '" + kv + "': expected name=value");
    }
    if (!out.emplace(kv.substr(0, eq), kv.substr(eq + 1)).second)
      throw UserError("--hp " + kv.substr(0, eq) + " is given twice; expected each name once");
  }
  return out;
}

std::map<std::string, std::string> parse_hyperparameter_text(std::string_view text) {
  std::map<std::string, std::string> values;
  std::istringstream lines{std::string(text)};
  std::string line;
  while (std::getline(lines, line)) {
    const std::string_view view = trim(line);
    if (view.empty() || view.front() == '#') continue;
    const auto equals = view.find('=');
    if (equals == std::string_view::npos) {
      throw UserError("hyperparameter line without '=': '" + std::string(view) + "'");
    }
    values[std::string(trim(view.substr(0, equals)))] = std::string(trim(view.substr(equals + 1)));
  }
  return values;
}

}  // namespace cradle::learn

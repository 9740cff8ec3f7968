// Named hyperparameters. Each learner lists its settings once (name, field, one-line doc); the
// table applies text overrides such as {"n_steps", "512"} with strict parsing and writes every
// value back as "name = value" lines: the config text stored in checkpoints, which
// parse_hyperparameter_text reads back into overrides that rebuild the same learner.
#pragma once

#include <map>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace cradle::learn {

class Hyperparameters {
 public:
  // A field: ints, longs, doubles, bools ("true"/"false"), strings, or int lists ("64,64"; ""
  // is the empty list).
  using Field = std::variant<int*, long*, double*, bool*, std::string*, std::vector<int>*>;

  // Registers a field; its current value is the default. Names are unique.
  void add(std::string name, Field field, std::string doc);
  // Sets the named fields. Throws UserError for an unknown name or a value that does not parse.
  void apply(const std::map<std::string, std::string>& overrides);
  bool contains(std::string_view name) const;
  // One "name = value" line per field, in registration order.
  std::string to_text() const;
  // One "name (default value): doc" line per field, for --help style listings.
  std::string describe() const;

 private:
  struct Entry {
    std::string name;
    Field field;
    std::string doc;
  };
  std::vector<Entry> entries_;
};

// Reads "name = value" lines (as written by Hyperparameters::to_text; blank lines and lines
// starting with '#' are skipped). Throws UserError for a line without '='.
std::map<std::string, std::string> parse_hyperparameter_text(std::string_view text);

// `--hp name=value` flags as overrides. UserError for a flag without a name or '=' and for a name
// given twice (one of its values would be dropped silently).
std::map<std::string, std::string> parse_hyperparameter_flags(
    const std::vector<std::string>& flags);

}  // namespace cradle::learn

// Validators shared by the subcommands' flags.
#pragma once

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <string>

namespace cradle::apps {

// A seed: a decimal integer from 0 to 2^64 - 1; negatives and larger values are refused instead
// of wrapping or saturating.
inline const CLI::Validator kSeed(
    [](std::string& text) -> std::string {
      const bool digits =
          !text.empty() && text.find_first_not_of("0123456789") == std::string::npos;
      errno = 0;
      if (digits) std::strtoull(text.c_str(), nullptr, 10);
      if (!digits || errno == ERANGE) {
        return "expected a seed from 0 to 18446744073709551615, got '" + text + "'";
      }
      return "";
    },
    "SEED");

// A finite number: CLI::Range compares with < and >, so NaN passes it; put this check before it.
inline const CLI::Validator kFinite(
    [](std::string& text) -> std::string {
      char* end = nullptr;
      const double value = std::strtod(text.c_str(), &end);
      if (end == text.c_str() || *end != '\0' || !std::isfinite(value)) {
        return "expected a finite number, got '" + text + "'";
      }
      return "";
    },
    "NUMBER");

}  // namespace cradle::apps

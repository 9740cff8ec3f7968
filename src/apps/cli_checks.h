// Validators shared by the subcommands' flags.
#pragma once

#include <CLI/CLI.hpp>
#include <cerrno>
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

}  // namespace cradle::apps

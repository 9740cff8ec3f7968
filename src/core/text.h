// User text quoted in a one-line error (core/error.h), and names listed in one.
#pragma once

#include <cctype>
#include <cstddef>
#include <cstdio>
#include <iterator>
#include <string>
#include <string_view>

namespace cradle {

// Control characters as \xNN (a newline would break the line); past `max` characters the text is
// cut with "...".
inline std::string printable(std::string_view text, std::size_t max = std::string::npos) {
  std::string out;
  for (const char c : text) {
    if (out.size() >= max) return out + "...";
    if (std::iscntrl(static_cast<unsigned char>(c))) {
      char code[8];
      std::snprintf(code, sizeof code, "\\x%02x", static_cast<unsigned char>(c));
      out += code;
    } else {
      out += c;
    }
  }
  return out;
}

// Names listed for a message: "a, b, c or d" (`last` is the word before the last name).
template <class Names>
std::string listed(const Names& names, std::string_view last = "or") {
  std::string out;
  std::size_t k = 0;
  for (const auto& name : names) {
    out += k == 0 ? "" : k + 1 == std::size(names) ? " " + std::string(last) + " " : ", ";
    out += name;
    ++k;
  }
  return out;
}

}  // namespace cradle

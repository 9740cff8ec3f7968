// User text quoted in a one-line error (core/error.h).
#pragma once

#include <cctype>
#include <cstddef>
#include <cstdio>
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

}  // namespace cradle

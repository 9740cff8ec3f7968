// Reading what the campaign commands write: the configuration lines of a campaign file or of a
// command's output, and how many of them hold a string. Shared by the TeachMyAgent campaign tests
// and the campaign tests of every kind.
#pragma once

#include <sstream>
#include <string>
#include <vector>

namespace cradle::test {

// The lines that configure runs: no comments, no blank lines, no "wrote ..." messages.
inline std::vector<std::string> config_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) {
    if (!l.empty() && l[0] != '#' && l.rfind("wrote", 0) != 0) lines.push_back(l);
  }
  return lines;
}

// How many of `lines` hold `needle`.
inline int count(const std::vector<std::string>& lines, const std::string& needle) {
  int n = 0;
  for (const std::string& l : lines) n += l.find(needle) != std::string::npos;
  return n;
}

}  // namespace cradle::test

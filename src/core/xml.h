// A small XML writer for generated MJCF: indented elements, escaped attributes, numbers printed in
// their shortest exact form so that a written model compiles to the same numbers.
#pragma once

#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace cradle {

using Attrs = std::vector<std::pair<std::string, std::string>>;

// Shortest decimal text that parses back to the same double (std::to_chars).
std::string num(double value);
// Space-separated numbers.
std::string nums(std::span<const double> values);
std::string nums(std::initializer_list<double> values);

class XmlWriter {
 public:
  explicit XmlWriter(int indent = 0) : depth_(indent) {}
  // <tag attrs...>; closed by close().
  XmlWriter& open(std::string_view tag, const Attrs& attrs = {});
  // <tag attrs.../>
  XmlWriter& leaf(std::string_view tag, const Attrs& attrs = {});
  XmlWriter& close();
  // <!-- text --> ("--" inside the text is broken up, as XML forbids it).
  XmlWriter& comment(std::string_view text);
  // Pre-formatted XML; each line is indented by the current depth.
  XmlWriter& raw(std::string_view xml);
  const std::string& str() const { return out_; }

 private:
  void start_line();
  void write_tag(std::string_view tag, const Attrs& attrs);
  std::string out_;
  std::vector<std::string> open_tags_;
  int depth_;
};

std::string xml_escape(std::string_view text);

}  // namespace cradle

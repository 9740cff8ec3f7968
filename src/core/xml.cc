#include "core/xml.h"

#include <charconv>
#include <cmath>

namespace cradle {

std::string num(double value) {
  // Negative zero prints as "0": the sign means nothing in a model file.
  if (value == 0) return "0";
  char buf[32];
  auto [end, ec] = std::to_chars(buf, buf + sizeof(buf), value);
  return ec == std::errc() ? std::string(buf, end) : std::string("nan");
}

std::string nums(std::span<const double> values) {
  std::string out;
  for (double v : values) {
    if (!out.empty()) out += ' ';
    out += num(v);
  }
  return out;
}

std::string nums(std::initializer_list<double> values) {
  return nums(std::span<const double>(values.begin(), values.size()));
}

std::string xml_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

void XmlWriter::start_line() { out_.append(2 * depth_, ' '); }

void XmlWriter::write_tag(std::string_view tag, const Attrs& attrs) {
  start_line();
  out_ += '<';
  out_ += tag;
  for (const auto& [key, value] : attrs) {
    out_ += ' ';
    out_ += key;
    out_ += "=\"";
    out_ += xml_escape(value);
    out_ += '"';
  }
}

XmlWriter& XmlWriter::open(std::string_view tag, const Attrs& attrs) {
  write_tag(tag, attrs);
  out_ += ">\n";
  open_tags_.emplace_back(tag);
  ++depth_;
  return *this;
}

XmlWriter& XmlWriter::leaf(std::string_view tag, const Attrs& attrs) {
  write_tag(tag, attrs);
  out_ += "/>\n";
  return *this;
}

XmlWriter& XmlWriter::close() {
  --depth_;
  start_line();
  out_ += "</" + open_tags_.back() + ">\n";
  open_tags_.pop_back();
  return *this;
}

XmlWriter& XmlWriter::comment(std::string_view text) {
  std::string safe(text);
  for (size_t pos = safe.find("--"); pos != std::string::npos; pos = safe.find("--", pos)) {
    safe.replace(pos, 2, "- -");
  }
  start_line();
  out_ += "<!--\n" + safe;
  if (!safe.empty() && safe.back() != '\n') out_ += '\n';
  start_line();
  out_ += "-->\n";
  return *this;
}

XmlWriter& XmlWriter::raw(std::string_view xml) {
  size_t begin = 0;
  while (begin < xml.size()) {
    size_t end = xml.find('\n', begin);
    if (end == std::string_view::npos) end = xml.size();
    std::string_view line = xml.substr(begin, end - begin);
    if (line.find_first_not_of(" \t\r") != std::string_view::npos) {
      start_line();
      out_ += line;
      out_ += '\n';
    }
    begin = end + 1;
  }
  return *this;
}

}  // namespace cradle

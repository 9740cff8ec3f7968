// Append-only JSON-lines logs: one JSON value per line, readable after a crash mid-write.
#pragma once

#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace cradle {

// Writes one JSON value per line through a stdio buffer. Opening an existing file in append mode
// first repairs an unterminated last line (a crash mid-write): kept and ended with '\n' if it
// parses, cut off otherwise, so appended lines never join a broken one.
class JsonlWriter {
 public:
  // Creates parent folders; append = false truncates. UserError if the file cannot be opened.
  explicit JsonlWriter(std::filesystem::path file, bool append = true);
  // Closes the file, swallowing errors: call flush() to learn about write failures.
  ~JsonlWriter() = default;
  JsonlWriter(JsonlWriter&&) = default;
  JsonlWriter& operator=(JsonlWriter&&) = default;

  // Buffers `entry` as one compact line; invalid UTF-8 in strings becomes U+FFFD. UserError if
  // the write fails.
  void write(const nlohmann::json& entry);
  // Hands buffered lines to the OS, and with sync = true to the disk (fsync). UserError on failure.
  void flush(bool sync = false);

 private:
  struct Closer {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  std::filesystem::path file_;
  std::unique_ptr<std::FILE, Closer> out_;
};

// What is wrong with an entry ("" when nothing is).
using JsonlCheck = std::function<std::string(const nlohmann::json& entry)>;

// Every line of a JSON-lines file, in order; blank lines are skipped. A malformed last line with
// no final newline (a crash mid-write) is ignored; any other malformed line, and an entry that
// `check` (when given) finds wrong, is a UserError naming the file and line number, as is a
// missing file.
std::vector<nlohmann::json> read_jsonl(const std::filesystem::path& file,
                                       const JsonlCheck& check = {});

}  // namespace cradle

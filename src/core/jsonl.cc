// JSON-lines writing through stdio, with partial-line repair on append, and tolerant reading.
#include "core/jsonl.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <system_error>
#include <utility>

#include "core/error.h"

namespace cradle {
namespace {

// Repairs an unterminated last line (a crash mid-write) before appending: ends it with '\n' if
// it parses as JSON, as read_jsonl would keep it, and cuts it off otherwise.
void repair_last_line(const std::filesystem::path& file) {
  std::error_code ec;
  std::uintmax_t size = std::filesystem::file_size(file, ec);
  if (ec || size == 0) return;  // missing or empty: nothing to repair
  std::ifstream in(file, std::ios::binary);
  // Scan backwards in blocks for the last newline; `keep` ends just past it.
  constexpr std::uintmax_t kBlock = 4096;
  std::uintmax_t keep = size;
  std::string block;
  while (keep > 0) {
    std::uintmax_t start = keep > kBlock ? keep - kBlock : 0;
    block.resize(keep - start);
    in.seekg(static_cast<std::streamoff>(start));
    in.read(block.data(), static_cast<std::streamsize>(block.size()));
    if (!in) return;  // unreadable: the open that follows reports it
    if (keep == size && block.back() == '\n') return;  // whole lines already
    std::size_t at = block.rfind('\n');
    if (at != std::string::npos) {
      keep = start + at + 1;
      break;
    }
    keep = start;
  }
  std::string tail(size - keep, '\0');
  in.seekg(static_cast<std::streamoff>(keep));
  in.read(tail.data(), static_cast<std::streamsize>(tail.size()));
  if (!in) return;
  in.close();
  if (nlohmann::json::accept(tail)) {
    std::ofstream(file, std::ios::binary | std::ios::app) << '\n';
    return;
  }
  std::filesystem::resize_file(file, keep, ec);
  if (ec) throw UserError("cannot repair " + file.string() + ": " + ec.message());
}

}  // namespace

JsonlWriter::JsonlWriter(std::filesystem::path file, bool append) : file_(std::move(file)) {
  std::filesystem::path folder = file_.parent_path();
  if (!folder.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(folder, ec);
    if (ec) {
      throw UserError("cannot open " + file_.string() + ": cannot create folder " +
                      folder.string() + ": " + ec.message());
    }
  }
  if (append) repair_last_line(file_);
  out_.reset(std::fopen(file_.c_str(), append ? "ab" : "wb"));
  if (!out_) throw UserError("cannot open " + file_.string() + ": " + std::strerror(errno));
}

void JsonlWriter::write(const nlohmann::json& entry) {
  std::string line = entry.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  line += '\n';
  if (std::fwrite(line.data(), 1, line.size(), out_.get()) != line.size()) {
    throw UserError("cannot write " + file_.string() + ": " + std::strerror(errno));
  }
}

void JsonlWriter::flush(bool sync) {
  if (std::fflush(out_.get()) != 0 || (sync && ::fsync(fileno(out_.get())) != 0)) {
    throw UserError("cannot write " + file_.string() + ": " + std::strerror(errno));
  }
}

std::vector<nlohmann::json> read_jsonl(const std::filesystem::path& file, const JsonlCheck& check) {
  // A folder opens as a stream but fails on the first read with a library message: named here.
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec))
    throw UserError(file.string() + " is a folder; expected a JSON-lines file");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw UserError("cannot read " + file.string());
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw UserError("cannot read " + file.string());

  std::vector<nlohmann::json> entries;
  std::size_t line_no = 0;
  for (std::size_t at = 0; at < text.size();) {
    ++line_no;
    std::size_t end = text.find('\n', at);
    bool last = end == std::string::npos;
    std::string_view line(text.data() + at, (last ? text.size() : end) - at);
    at = last ? text.size() : end + 1;
    if (line.find_first_not_of(" \t\r") == std::string_view::npos) continue;
    nlohmann::json entry = nlohmann::json::parse(line, nullptr, /*allow_exceptions=*/false);
    if (entry.is_discarded()) {
      if (last) break;  // cut short by a crash mid-write
      throw UserError(file.string() + ":" + std::to_string(line_no) + ": malformed JSON line");
    }
    if (check) {
      const std::string problem = check(entry);
      if (!problem.empty()) {
        throw UserError(file.string() + ":" + std::to_string(line_no) + ": " + problem);
      }
    }
    entries.push_back(std::move(entry));
  }
  return entries;
}

}  // namespace cradle

#include "core/sealed_file.h"

#include <fcntl.h>
#include <unistd.h>
#include <zlib.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <system_error>
#include <vector>

#include "core/error.h"

namespace cradle {
namespace {

constexpr std::string_view kMagic = "CRADLE-SEALED 1\n";

std::string hex(std::uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "%08x", v);
  return buf;
}

// Writes all bytes to a file descriptor; false with errno set on failure.
bool write_all(int fd, std::string_view bytes) {
  while (!bytes.empty()) {
    const ssize_t n = ::write(fd, bytes.data(), bytes.size());
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    bytes.remove_prefix(static_cast<size_t>(n));
  }
  return true;
}

}  // namespace

std::uint32_t crc32_of(std::string_view bytes) {
  uLong crc = ::crc32(0L, Z_NULL, 0);
  // zlib takes uInt lengths: feed large inputs in chunks.
  constexpr size_t kChunk = 1u << 30;
  for (size_t at = 0; at < bytes.size(); at += kChunk) {
    const size_t n = std::min(kChunk, bytes.size() - at);
    crc = ::crc32(crc, reinterpret_cast<const Bytef*>(bytes.data() + at), static_cast<uInt>(n));
  }
  return static_cast<std::uint32_t>(crc);
}

void write_atomically(const std::filesystem::path& file, std::string_view bytes) {
  std::error_code ec;
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path(), ec);
  std::filesystem::path temp = file;
  temp += ".tmp";
  // Each failure removes the temp file and leaves `file` as it was.
  auto fail = [&](int fd, const char* step) {
    const int saved = errno;
    if (fd >= 0) ::close(fd);
    std::filesystem::remove(temp, ec);
    throw UserError(file.string() + ": cannot write (" + step + ": " + std::strerror(saved) + ")");
  };
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) fail(fd, "open");
  if (!write_all(fd, bytes)) fail(fd, "write");
  if (::fsync(fd) != 0) fail(fd, "fsync");
  if (::close(fd) != 0) fail(-1, "close");
  if (std::rename(temp.c_str(), file.c_str()) != 0) fail(-1, "rename");
}

void write_sealed(const std::filesystem::path& file, const Sections& sections) {
  std::string out(kMagic);
  out += std::to_string(sections.size()) + "\n";
  for (const auto& [name, bytes] : sections) {
    out += name + "\t" + std::to_string(bytes.size()) + "\t" + hex(crc32_of(bytes)) + "\n";
  }
  for (const auto& section : sections) out += section.second;
  out += "END " + hex(crc32_of(out)) + "\n";
  write_atomically(file, out);
}

bool looks_sealed(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::string head(kMagic.size(), '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  return in && head == kMagic;
}

Sections read_sealed(const std::filesystem::path& file, std::string_view what) {
  const std::string prefix = file.string() + ": ";
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) {
    throw UserError(prefix + "no such " + std::string(what) + " file");
  }
  std::ifstream in(file, std::ios::binary);
  if (!in)
    throw UserError(prefix + "cannot read " + std::string(what) + ": " + std::strerror(errno));
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw UserError(prefix + "cannot read " + std::string(what));
  auto damaged = [&](const std::string& why) {
    return UserError(prefix + "damaged or not a Cradle " + std::string(what) + " (" + why + ")");
  };
  if (!text.starts_with(kMagic)) throw damaged("no Cradle header");

  // The trailer: its CRC covers everything before it.
  constexpr size_t kTrailer = 4 + 8 + 1;  // "END " + 8 hex digits + '\n'
  if (text.size() < kMagic.size() + kTrailer) throw damaged("truncated");
  const size_t end = text.size() - kTrailer;
  if (text.compare(end, 4, "END ") != 0 || text.back() != '\n') throw damaged("truncated");
  if (hex(crc32_of(std::string_view(text).substr(0, end))) != text.substr(end + 4, 8)) {
    throw damaged("checksum mismatch");
  }

  // The section table, then the payloads in order.
  std::istringstream header(text.substr(kMagic.size(), end - kMagic.size()));
  long count = -1;
  std::string line;
  if (!std::getline(header, line) || (count = std::strtol(line.c_str(), nullptr, 10)) < 0 ||
      count > 4096 || std::to_string(count) != line) {
    throw damaged("bad section count");
  }
  struct Entry {
    std::string name;
    size_t bytes;
    std::string crc;
  };
  std::vector<Entry> entries;
  size_t at = kMagic.size() + line.size() + 1;
  for (long k = 0; k < count; ++k) {
    if (!std::getline(header, line)) throw damaged("truncated section table");
    at += line.size() + 1;
    const size_t t1 = line.find('\t'), t2 = line.rfind('\t');
    if (t1 == std::string::npos || t1 == t2) throw damaged("bad section table");
    const std::string size_text = line.substr(t1 + 1, t2 - t1 - 1);
    char* stop = nullptr;
    const unsigned long long bytes = std::strtoull(size_text.c_str(), &stop, 10);
    if (size_text.empty() || *stop != '\0' || bytes > text.size()) {
      throw damaged("bad section size");
    }
    entries.push_back({line.substr(0, t1), static_cast<size_t>(bytes), line.substr(t2 + 1)});
  }
  Sections sections;
  for (const Entry& e : entries) {
    if (at + e.bytes > end) throw damaged("section '" + e.name + "' runs past the end");
    std::string bytes = text.substr(at, e.bytes);
    at += e.bytes;
    if (hex(crc32_of(bytes)) != e.crc) throw damaged("section '" + e.name + "' checksum mismatch");
    sections[e.name] = std::move(bytes);
  }
  if (at != end) throw damaged("unexpected bytes after the sections");
  return sections;
}

}  // namespace cradle

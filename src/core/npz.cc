// .npy encoding (format 1.0, header padded to 64 bytes), zip writing (local headers, central
// directory, end record; methods 0 and 8 via zlib) and the matching reader.
#include "core/npz.h"

#include <fcntl.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <type_traits>
#include <utility>

#include "core/error.h"

namespace cradle {
namespace {

static_assert(std::endian::native == std::endian::little, "npz encoding assumes little endian");

using Bytes = std::vector<std::uint8_t>;

constexpr std::uint32_t kLocalSig = 0x04034b50;
constexpr std::uint32_t kCentralSig = 0x02014b50;
constexpr std::uint32_t kEndSig = 0x06054b50;
constexpr std::size_t kLocalSize = 30;    // local file header without name
constexpr std::size_t kCentralSize = 46;  // central directory header without name
constexpr std::size_t kEndSize = 22;      // end of central directory record without comment
constexpr std::uint16_t kVersion = 20;    // zip 2.0: deflate, no zip64
constexpr std::uint16_t kMadeBy = (3 << 8) | kVersion;       // unix host, so unzip keeps 0644
constexpr std::uint16_t kUtf8Flag = 0x0800;                  // member names are UTF-8
constexpr std::uint16_t kDosDate = (0 << 9) | (1 << 5) | 1;  // 1980-01-01, for reproducible files
constexpr std::uint32_t kUnixMode = 0100644u << 16;
constexpr std::uint64_t kZipMax = 0xFFFFFFFEu;  // 0xFFFFFFFF itself means "see zip64"
constexpr std::size_t kMaxMembers = 0xFFFE;
constexpr std::size_t kMaxDims = 32;  // numpy's NPY_MAXDIMS
constexpr char kMagic[] = "\x93NUMPY";

// Little-endian appends.
void put16(Bytes& out, std::uint16_t v) {
  out.push_back(static_cast<std::uint8_t>(v));
  out.push_back(static_cast<std::uint8_t>(v >> 8));
}
void put32(Bytes& out, std::uint32_t v) {
  put16(out, static_cast<std::uint16_t>(v));
  put16(out, static_cast<std::uint16_t>(v >> 16));
}
void put_text(Bytes& out, std::string_view s) { out.insert(out.end(), s.begin(), s.end()); }

// Product of a shape, std::invalid_argument on overflow.
std::size_t shape_count(const std::vector<std::size_t>& shape) {
  std::size_t n = 1;
  for (std::size_t d : shape) {
    if (d != 0 && n > std::numeric_limits<std::size_t>::max() / d) {
      throw std::invalid_argument("npz: shape product overflows");
    }
    n *= d;
  }
  return n;
}

// The shape as a Python tuple: "()", "(3,)", "(3, 4)".
std::string shape_tuple(const std::vector<std::size_t>& shape) {
  std::string s = "(";
  for (std::size_t i = 0; i < shape.size(); ++i) {
    if (i > 0) s += ", ";
    s += std::to_string(shape[i]);
  }
  if (shape.size() == 1) s += ",";
  return s + ")";
}

// A .npy 1.0 header: magic, version, length, dict, spaces and '\n' up to a multiple of 64.
Bytes npy_header(const std::string& descr, const std::vector<std::size_t>& shape) {
  std::string dict =
      "{'descr': '" + descr + "', 'fortran_order': False, 'shape': " + shape_tuple(shape) + ", }";
  std::size_t prefix = 10;
  std::size_t total = (prefix + dict.size() + 1 + 63) / 64 * 64;
  dict.append(total - prefix - dict.size() - 1, ' ');
  dict += '\n';
  Bytes out;
  put_text(out, std::string_view(kMagic, 6));
  out.push_back(1);
  out.push_back(0);
  put16(out, static_cast<std::uint16_t>(dict.size()));
  put_text(out, dict);
  return out;
}

// Raw deflate (no zlib or gzip wrapper), as zip method 8 wants.
Bytes deflate_raw(const Bytes& in) {
  z_stream z{};
  if (deflateInit2(&z, Z_DEFAULT_COMPRESSION, Z_DEFLATED, -15, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
    throw std::runtime_error("npz: zlib deflateInit2 failed");
  }
  Bytes out(deflateBound(&z, in.size()));
  z.next_in = const_cast<Bytef*>(in.data());
  z.avail_in = static_cast<uInt>(in.size());
  z.next_out = out.data();
  z.avail_out = static_cast<uInt>(out.size());
  int rc = deflate(&z, Z_FINISH);
  std::size_t written = z.total_out;
  deflateEnd(&z);
  if (rc != Z_STREAM_END) throw std::runtime_error("npz: zlib deflate failed");
  out.resize(written);
  return out;
}

// Writes all of `data` to `fd`, retrying short writes; false on error (errno set).
bool write_all(int fd, const std::uint8_t* data, std::size_t size) {
  while (size > 0) {
    ssize_t n = ::write(fd, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    data += n;
    size -= static_cast<std::size_t>(n);
  }
  return true;
}

// Creates a fresh, exclusive temp file next to `file`; returns its fd (-1 with errno on failure).
int open_temp(const std::filesystem::path& file, std::filesystem::path& temp) {
  std::random_device seed;
  for (int attempt = 0; attempt < 64; ++attempt) {
    char suffix[16];
    std::snprintf(suffix, sizeof suffix, ".%08x.tmp", static_cast<unsigned>(seed()));
    temp = file.parent_path() / ("." + file.filename().string() + suffix);
    int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0 || errno != EEXIST) return fd;
  }
  return -1;
}

// A malformed input, turned into a UserError naming the file by read_npz.
struct Malformed : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Bounds-checked little-endian reads from a byte buffer.
struct Cursor {
  const Bytes& buf;
  std::size_t pos;

  void need(std::size_t n) const {
    if (pos > buf.size() || n > buf.size() - pos) throw Malformed("truncated zip structure");
  }
  std::uint16_t u16() {
    need(2);
    std::uint16_t v = static_cast<std::uint16_t>(buf[pos] | (buf[pos + 1] << 8));
    pos += 2;
    return v;
  }
  std::uint32_t u32() {
    std::uint32_t lo = u16();
    return lo | (static_cast<std::uint32_t>(u16()) << 16);
  }
  std::string text(std::size_t n) {
    need(n);
    std::string s(buf.begin() + static_cast<std::ptrdiff_t>(pos),
                  buf.begin() + static_cast<std::ptrdiff_t>(pos + n));
    pos += n;
    return s;
  }
};

// Inflates raw deflate data that must come out as exactly `size` bytes.
Bytes inflate_raw(const std::uint8_t* in, std::size_t in_size, std::size_t size) {
  z_stream z{};
  if (inflateInit2(&z, -15) != Z_OK) throw std::runtime_error("npz: zlib inflateInit2 failed");
  Bytes out(size);
  z.next_in = const_cast<Bytef*>(in);
  z.avail_in = static_cast<uInt>(in_size);
  z.next_out = out.data();
  z.avail_out = static_cast<uInt>(out.size());
  int rc = inflate(&z, Z_FINISH);
  std::size_t produced = z.total_out;
  inflateEnd(&z);
  if (rc != Z_STREAM_END || produced != size) throw Malformed("corrupt deflate data");
  return out;
}

// Position just past ":" of `'key':` in a .npy header dict, skipping spaces.
std::size_t dict_value(std::string_view dict, std::string_view key) {
  for (char quote : {'\'', '"'}) {
    std::string pattern = quote + std::string(key) + quote;
    std::size_t at = dict.find(pattern);
    if (at == std::string_view::npos) continue;
    at += pattern.size();
    while (at < dict.size() && dict[at] == ' ') ++at;
    if (at < dict.size() && dict[at] == ':') {
      ++at;
      while (at < dict.size() && dict[at] == ' ') ++at;
      return at;
    }
  }
  throw Malformed("npy header lacks '" + std::string(key) + "'");
}

// Parses a .npy file (versions 1 to 3) into an array.
NpyArray parse_npy(const Bytes& npy) {
  if (npy.size() < 10 || std::memcmp(npy.data(), kMagic, 6) != 0) throw Malformed("not .npy data");
  int major = npy[6];
  if (major < 1 || major > 3) throw Malformed("unsupported .npy version " + std::to_string(major));
  Cursor cur{npy, 8};
  std::size_t header_size = major == 1 ? cur.u16() : cur.u32();
  std::string dict = cur.text(header_size);

  NpyArray array;
  std::size_t at = dict_value(dict, "descr");
  if (at >= dict.size() || (dict[at] != '\'' && dict[at] != '"')) {
    throw Malformed("structured dtypes are not supported");
  }
  std::size_t end = dict.find(dict[at], at + 1);
  if (end == std::string::npos) throw Malformed("npy header has an unterminated descr");
  array.descr = dict.substr(at + 1, end - at - 1);
  if (array.descr.size() < 2 ||
      std::string_view("<>|=").find(array.descr[0]) == std::string::npos) {
    throw Malformed("unsupported dtype descr '" + array.descr + "'");
  }

  at = dict_value(dict, "fortran_order");
  if (dict.compare(at, 4, "True") == 0) throw Malformed("Fortran-order arrays are not supported");
  if (dict.compare(at, 5, "False") != 0) throw Malformed("npy header has a bad fortran_order");

  at = dict_value(dict, "shape");
  end = dict.find(')', at);
  if (at >= dict.size() || dict[at] != '(' || end == std::string::npos) {
    throw Malformed("npy header has a bad shape");
  }
  for (std::size_t i = at + 1; i < end;) {
    if (dict[i] == ' ' || dict[i] == ',') {
      ++i;
      continue;
    }
    std::size_t digits = i;
    while (digits < end && dict[digits] >= '0' && dict[digits] <= '9') ++digits;
    if (digits == i || digits - i > 19) throw Malformed("npy header has a bad shape");
    array.shape.push_back(std::stoull(dict.substr(i, digits - i)));
    i = digits;
  }

  std::size_t data_at = cur.pos;
  std::size_t count = 0;
  try {
    count = array.count();
  } catch (const std::invalid_argument&) {
    throw Malformed("npy shape is too large");
  }
  std::size_t item = array.item_size();
  if (item != 0 && count > std::numeric_limits<std::size_t>::max() / item) {
    throw Malformed("npy shape is too large");
  }
  if (npy.size() - data_at != count * item) {
    throw Malformed("npy data size does not match its shape and dtype");
  }
  array.bytes.assign(npy.begin() + static_cast<std::ptrdiff_t>(data_at), npy.end());
  return array;
}

// Reads all members of a zip held in memory.
std::map<std::string, NpyArray> parse_npz(const Bytes& zip) {
  if (zip.size() < kEndSize) throw Malformed("not a zip archive");
  std::size_t end = zip.size() - kEndSize;
  std::size_t lowest = end > 0xFFFF ? end - 0xFFFF : 0;  // the comment is at most 65535 bytes
  while (Cursor{zip, end}.u32() != kEndSig) {
    if (end == lowest) throw Malformed("not a zip archive (no end of central directory)");
    --end;
  }
  Cursor eocd{zip, end + 10};
  std::size_t entries = eocd.u16();
  std::uint32_t dir_size = eocd.u32();
  std::uint32_t dir_offset = eocd.u32();
  if (entries == 0xFFFF || dir_size == 0xFFFFFFFF || dir_offset == 0xFFFFFFFF) {
    throw Malformed("zip64 archives are not supported");
  }

  std::map<std::string, NpyArray> arrays;
  Cursor dir{zip, dir_offset};
  for (std::size_t i = 0; i < entries; ++i) {
    if (dir.u32() != kCentralSig) throw Malformed("bad central directory");
    dir.pos += 4;  // version made by, version needed
    std::uint16_t flags = dir.u16();
    std::uint16_t method = dir.u16();
    dir.pos += 4;  // time, date
    std::uint32_t crc = dir.u32();
    std::uint32_t packed = dir.u32();
    std::uint32_t size = dir.u32();
    std::size_t name_size = dir.u16();
    std::size_t extra_size = dir.u16();
    std::size_t comment_size = dir.u16();
    dir.pos += 8;  // disk, internal and external attributes
    std::uint32_t offset = dir.u32();
    std::string name = dir.text(name_size);
    dir.pos += extra_size + comment_size;
    if (packed == 0xFFFFFFFF || size == 0xFFFFFFFF || offset == 0xFFFFFFFF) {
      throw Malformed("zip64 members are not supported");
    }
    if (flags & 1) throw Malformed("member '" + name + "' is encrypted");
    if (method != 0 && method != 8) {
      throw Malformed("member '" + name + "' uses unsupported method " + std::to_string(method));
    }

    Cursor local{zip, offset};
    if (local.u32() != kLocalSig) throw Malformed("bad local header of '" + name + "'");
    local.pos = offset + 26;
    std::size_t skip = local.u16();
    skip += local.u16();
    local.pos += skip;
    local.need(packed);
    const std::uint8_t* data = zip.data() + local.pos;
    Bytes npy = method == 8 ? inflate_raw(data, packed, size) : Bytes(data, data + packed);
    if (npy.size() != size) throw Malformed("member '" + name + "' has the wrong size");
    if (crc32_z(0, npy.data(), npy.size()) != crc) {
      throw Malformed("crc mismatch in '" + name + "'");
    }

    constexpr std::string_view kExt = ".npy";
    if (!name.ends_with(kExt)) throw Malformed("member '" + name + "' is not a .npy file");
    name.resize(name.size() - kExt.size());
    try {
      arrays[name] = parse_npy(npy);
    } catch (const Malformed& e) {
      throw Malformed("member '" + name + ".npy': " + e.what());
    }
  }
  return arrays;
}

// The numpy descr of each element type the writer takes.
template <typename T>
constexpr const char* descr_of() {
  if constexpr (std::is_same_v<T, double>) return "<f8";
  if constexpr (std::is_same_v<T, float>) return "<f4";
  if constexpr (std::is_same_v<T, std::int32_t>) return "<i4";
  if constexpr (std::is_same_v<T, std::int64_t>) return "<i8";
  if constexpr (std::is_same_v<T, std::uint8_t>) return "|u1";
}

}  // namespace

NpzWriter::NpzWriter(std::filesystem::path file, bool compress)
    : file_(std::move(file)), compress_(compress) {}

NpzWriter::~NpzWriter() {
  try {
    close();
  } catch (...) {
    // A destructor must not throw; callers who care call close() themselves.
  }
}

void NpzWriter::add_raw(const std::string& name, const std::string& descr,
                        std::vector<std::size_t> shape, std::size_t count, const void* data,
                        std::size_t bytes) {
  if (closed_) throw std::invalid_argument("npz: add('" + name + "') after close()");
  if (name.empty()) throw std::invalid_argument("npz: array name is empty");
  std::string member = name + ".npy";
  if (member.size() > 0xFFFF) throw std::invalid_argument("npz: array name is too long");
  for (const Member& m : members_) {
    if (m.name == member) throw std::invalid_argument("npz: array '" + name + "' added twice");
  }
  if (shape.size() > kMaxDims) {
    throw std::invalid_argument("npz: array '" + name + "' has more than 32 dimensions");
  }
  if (shape_count(shape) != count) {
    throw std::invalid_argument("npz: array '" + name + "' has " + std::to_string(count) +
                                " elements but shape " + shape_tuple(shape));
  }

  Bytes npy = npy_header(descr, shape);
  if (bytes > kZipMax - npy.size()) {
    throw UserError("npz: array '" + name + "' is 4 GiB or more; zip64 is not supported");
  }
  const auto* begin = static_cast<const std::uint8_t*>(data);
  if (bytes > 0) npy.insert(npy.end(), begin, begin + bytes);

  Member m{.name = std::move(member),
           .crc = static_cast<std::uint32_t>(crc32_z(0, npy.data(), npy.size())),
           .size = npy.size()};
  if (compress_) {
    Bytes packed = deflate_raw(npy);
    if (packed.size() < npy.size()) {
      m.deflated = true;
      npy = std::move(packed);
    }
  }
  m.payload = std::move(npy);
  members_.push_back(std::move(m));
}

void NpzWriter::add(const std::string& name, std::span<const double> data,
                    std::vector<std::size_t> shape) {
  add_raw(name, descr_of<double>(), std::move(shape), data.size(), data.data(), data.size_bytes());
}
void NpzWriter::add(const std::string& name, std::span<const float> data,
                    std::vector<std::size_t> shape) {
  add_raw(name, descr_of<float>(), std::move(shape), data.size(), data.data(), data.size_bytes());
}
void NpzWriter::add(const std::string& name, std::span<const std::int32_t> data,
                    std::vector<std::size_t> shape) {
  add_raw(name, descr_of<std::int32_t>(), std::move(shape), data.size(), data.data(),
          data.size_bytes());
}
void NpzWriter::add(const std::string& name, std::span<const std::int64_t> data,
                    std::vector<std::size_t> shape) {
  add_raw(name, descr_of<std::int64_t>(), std::move(shape), data.size(), data.data(),
          data.size_bytes());
}
void NpzWriter::add(const std::string& name, std::span<const std::uint8_t> data,
                    std::vector<std::size_t> shape) {
  add_raw(name, descr_of<std::uint8_t>(), std::move(shape), data.size(), data.data(),
          data.size_bytes());
}

void NpzWriter::add_strings(const std::string& name, const std::vector<std::string>& values) {
  std::size_t width = 1;  // numpy's shortest byte-string dtype is S1
  for (const std::string& v : values) width = std::max(width, v.size());
  if (!values.empty() && width > kZipMax / values.size()) {
    throw UserError("npz: array '" + name + "' is 4 GiB or more; zip64 is not supported");
  }
  Bytes packed(values.size() * width, 0);
  for (std::size_t i = 0; i < values.size(); ++i) {
    std::copy(values[i].begin(), values[i].end(),
              packed.begin() + static_cast<std::ptrdiff_t>(i * width));
  }
  add_raw(name, "|S" + std::to_string(width), {values.size()}, values.size(), packed.data(),
          packed.size());
}

void NpzWriter::close() {
  if (closed_) return;
  closed_ = true;
  std::vector<Member> members = std::move(members_);
  members_.clear();
  auto fail = [&](const std::string& why) -> UserError {
    return UserError("cannot write " + file_.string() + ": " + why);
  };
  if (members.size() > kMaxMembers) throw fail("more than 65534 arrays; zip64 is not supported");

  std::filesystem::path folder = file_.parent_path();
  if (!folder.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(folder, ec);
    if (ec) throw fail("cannot create folder " + folder.string() + ": " + ec.message());
  }
  std::filesystem::path temp;
  int fd = open_temp(file_, temp);
  if (fd < 0) throw fail(std::strerror(errno));

  // Everything below removes the temp file before throwing.
  auto abandon = [&](const std::string& why) -> UserError {
    if (fd >= 0) ::close(fd);
    ::unlink(temp.c_str());
    return fail(why);
  };
  Bytes dir;
  std::uint64_t offset = 0;
  for (const Member& m : members) {
    if (offset > kZipMax) throw abandon("archive is 4 GiB or more; zip64 is not supported");
    std::uint32_t packed = static_cast<std::uint32_t>(m.payload.size());
    std::uint16_t method = m.deflated ? 8 : 0;
    std::uint16_t name_size = static_cast<std::uint16_t>(m.name.size());
    Bytes local;
    put32(local, kLocalSig);
    for (std::uint16_t v : {kVersion, kUtf8Flag, method, std::uint16_t{0}, kDosDate}) {
      put16(local, v);
    }
    put32(local, m.crc);
    put32(local, packed);
    put32(local, static_cast<std::uint32_t>(m.size));
    put16(local, name_size);
    put16(local, 0);
    put_text(local, m.name);

    put32(dir, kCentralSig);
    for (std::uint16_t v : {kMadeBy, kVersion, kUtf8Flag, method, std::uint16_t{0}, kDosDate}) {
      put16(dir, v);
    }
    put32(dir, m.crc);
    put32(dir, packed);
    put32(dir, static_cast<std::uint32_t>(m.size));
    for (std::uint16_t v :
         {name_size, std::uint16_t{0}, std::uint16_t{0}, std::uint16_t{0}, std::uint16_t{0}}) {
      put16(dir, v);  // name length, extra, comment, disk, internal attributes
    }
    put32(dir, kUnixMode);
    put32(dir, static_cast<std::uint32_t>(offset));
    put_text(dir, m.name);

    if (!write_all(fd, local.data(), local.size()) ||
        !write_all(fd, m.payload.data(), m.payload.size())) {
      throw abandon(std::strerror(errno));
    }
    offset += local.size() + m.payload.size();
  }
  if (offset > kZipMax || dir.size() > kZipMax - offset) {
    throw abandon("archive is 4 GiB or more; zip64 is not supported");
  }
  Bytes end;
  put32(end, kEndSig);
  std::uint16_t count = static_cast<std::uint16_t>(members.size());
  for (std::uint16_t v : {std::uint16_t{0}, std::uint16_t{0}, count, count}) put16(end, v);
  put32(end, static_cast<std::uint32_t>(dir.size()));
  put32(end, static_cast<std::uint32_t>(offset));
  put16(end, 0);
  if (!write_all(fd, dir.data(), dir.size()) || !write_all(fd, end.data(), end.size()) ||
      ::fsync(fd) != 0) {
    throw abandon(std::strerror(errno));
  }
  int rc = ::close(fd);
  fd = -1;
  if (rc != 0) throw abandon(std::strerror(errno));
  if (::rename(temp.c_str(), file_.c_str()) != 0) throw abandon(std::strerror(errno));

  // Make the rename itself durable; failure here loses nothing already visible.
  int dir_fd = ::open(folder.empty() ? "." : folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir_fd >= 0) {
    ::fsync(dir_fd);
    ::close(dir_fd);
  }
}

std::size_t NpyArray::item_size() const {
  std::size_t n = 0;
  for (std::size_t i = 2; i < descr.size() && descr[i] >= '0' && descr[i] <= '9'; ++i) {
    n = n * 10 + static_cast<std::size_t>(descr[i] - '0');
  }
  return descr.size() > 1 && descr[1] == 'U' ? 4 * n : n;  // 'U' counts UCS-4 characters
}

std::size_t NpyArray::count() const { return shape_count(shape); }

template <typename T>
std::vector<T> NpyArray::values() const {
  if (descr != descr_of<T>()) {
    throw std::invalid_argument(std::string("npz: array has dtype ") + descr + ", not " +
                                descr_of<T>());
  }
  std::vector<T> out(bytes.size() / sizeof(T));
  if (!out.empty()) std::memcpy(out.data(), bytes.data(), out.size() * sizeof(T));
  return out;
}

template std::vector<double> NpyArray::values<double>() const;
template std::vector<float> NpyArray::values<float>() const;
template std::vector<std::int32_t> NpyArray::values<std::int32_t>() const;
template std::vector<std::int64_t> NpyArray::values<std::int64_t>() const;
template std::vector<std::uint8_t> NpyArray::values<std::uint8_t>() const;

std::vector<std::string> NpyArray::strings() const {
  if (descr.size() < 3 || descr[1] != 'S') {
    throw std::invalid_argument("npz: array has dtype " + descr + ", not a byte string");
  }
  std::size_t width = item_size();
  std::vector<std::string> out;
  for (std::size_t at = 0; width > 0 && at + width <= bytes.size(); at += width) {
    std::size_t n = width;
    while (n > 0 && bytes[at + n - 1] == 0) --n;
    out.emplace_back(bytes.begin() + static_cast<std::ptrdiff_t>(at),
                     bytes.begin() + static_cast<std::ptrdiff_t>(at + n));
  }
  if (width == 0) out.resize(count());
  return out;
}

std::map<std::string, NpyArray> read_npz(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw UserError("cannot read npz file " + file.string());
  Bytes zip((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw UserError("cannot read npz file " + file.string());
  try {
    return parse_npz(zip);
  } catch (const Malformed& e) {
    throw UserError("bad npz file " + file.string() + ": " + e.what());
  }
}

}  // namespace cradle

// .npy encoding (format 1.0, header padded to 64 bytes) and parsing; the zip container around the
// members is libzip's.
#include "core/npz.h"

#include <zip.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <fstream>
#include <limits>
#include <memory>
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

constexpr std::uint16_t kDosDate = (0 << 9) | (1 << 5) | 1;  // 1980-01-01, for reproducible files
constexpr std::uint32_t kUnixMode = 0100644u << 16;          // so unzip keeps 0644
constexpr std::size_t kMaxDims = 32;                         // numpy's NPY_MAXDIMS
constexpr char kMagic[] = "\x93NUMPY";

// Little-endian appends.
void put16(Bytes& out, std::uint16_t v) {
  out.push_back(static_cast<std::uint8_t>(v));
  out.push_back(static_cast<std::uint8_t>(v >> 8));
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

// The numpy descr of each element type the writer takes.
template <typename T>
constexpr const char* descr_of() {
  if constexpr (std::is_same_v<T, double>) return "<f8";
  if constexpr (std::is_same_v<T, float>) return "<f4";
  if constexpr (std::is_same_v<T, std::int32_t>) return "<i4";
  if constexpr (std::is_same_v<T, std::int64_t>) return "<i8";
  if constexpr (std::is_same_v<T, std::uint8_t>) return "|u1";
}

// libzip's message for an archive's last error.
std::string zip_message(zip_t* zip) { return zip_strerror(zip); }

// Reads every member of an opened archive.
std::map<std::string, NpyArray> read_members(zip_t* zip) {
  std::map<std::string, NpyArray> arrays;
  const zip_int64_t entries = zip_get_num_entries(zip, 0);
  for (zip_int64_t i = 0; i < entries; ++i) {
    zip_stat_t stat;
    if (zip_stat_index(zip, i, 0, &stat) != 0) throw Malformed(zip_message(zip));
    std::string name = stat.name;
    // libzip checks the crc when a member is read to its end.
    zip_file_t* member = zip_fopen_index(zip, i, 0);
    if (!member) throw Malformed("member '" + name + "': " + zip_message(zip));
    Bytes npy(stat.size);
    const zip_int64_t got = zip_fread(member, npy.data(), npy.size());
    std::string error = got < 0 ? zip_file_strerror(member) : "";
    // One more read reaches the end, where libzip compares the crc.
    char probe;
    if (got >= 0 && zip_fread(member, &probe, 1) != 0) error = zip_file_strerror(member);
    zip_fclose(member);
    if (!error.empty()) throw Malformed("member '" + name + "': " + error);
    if (static_cast<zip_uint64_t>(got) != stat.size) {
      throw Malformed("member '" + name + "' has the wrong size");
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
  const auto* begin = static_cast<const std::uint8_t*>(data);
  if (bytes > 0) npy.insert(npy.end(), begin, begin + bytes);
  members_.push_back({.name = std::move(member), .npy = std::move(npy)});
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
  std::filesystem::path folder = file_.parent_path();
  if (!folder.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(folder, ec);
    if (ec) throw fail("cannot create folder " + folder.string() + ": " + ec.message());
  }

  // libzip writes a temp file beside the target and renames it on zip_close (atomic); it writes
  // no file for an archive without members, so that one (22 bytes: the end record) is ours.
  if (members.empty()) {
    Bytes end = {0x50, 0x4b, 0x05, 0x06};
    for (int k = 0; k < 9; ++k) put16(end, 0);
    const std::filesystem::path temp = file_.string() + ".tmp";
    {
      std::ofstream out(temp, std::ios::binary | std::ios::trunc);
      out.write(reinterpret_cast<const char*>(end.data()),
                static_cast<std::streamsize>(end.size()));
      if (!out) throw fail("cannot write " + temp.string());
    }
    std::error_code ec;
    std::filesystem::rename(temp, file_, ec);
    if (ec) {
      std::filesystem::remove(temp, ec);
      throw fail("cannot rename the temp file");
    }
    return;
  }
  int error = 0;
  zip_t* zip = zip_open(file_.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &error);
  if (!zip) {
    zip_error_t e;
    zip_error_init_with_code(&e, error);
    const std::string why = zip_error_strerror(&e);
    zip_error_fini(&e);
    throw fail(why);
  }
  // Members in add() order with a fixed date, so equal arrays give equal files.
  for (const Member& m : members) {
    zip_source_t* source = zip_source_buffer(zip, m.npy.data(), m.npy.size(), 0);
    const zip_int64_t index =
        source ? zip_file_add(zip, m.name.c_str(), source, ZIP_FL_ENC_UTF_8) : -1;
    if (index < 0) {
      if (source) zip_source_free(source);
      const std::string why = zip_message(zip);
      zip_discard(zip);
      throw fail(why);
    }
    if (zip_set_file_compression(zip, index, compress_ ? ZIP_CM_DEFLATE : ZIP_CM_STORE, 0) != 0 ||
        zip_file_set_dostime(zip, index, 0, kDosDate, 0) != 0 ||
        zip_file_set_external_attributes(zip, index, 0, ZIP_OPSYS_UNIX, kUnixMode) != 0) {
      const std::string why = zip_message(zip);
      zip_discard(zip);
      throw fail(why);
    }
  }
  if (zip_close(zip) != 0) {
    const std::string why = zip_message(zip);
    zip_discard(zip);
    throw fail(why);
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
  if (!std::filesystem::is_regular_file(file)) {
    throw UserError("cannot read npz file " + file.string());
  }
  int error = 0;
  zip_t* zip = zip_open(file.c_str(), ZIP_RDONLY | ZIP_CHECKCONS, &error);
  if (!zip) {
    zip_error_t e;
    zip_error_init_with_code(&e, error);
    const std::string why = zip_error_strerror(&e);
    zip_error_fini(&e);
    throw UserError("bad npz file " + file.string() + ": " + why);
  }
  try {
    auto arrays = read_members(zip);
    zip_discard(zip);
    return arrays;
  } catch (const Malformed& e) {
    zip_discard(zip);
    throw UserError("bad npz file " + file.string() + ": " + e.what());
  }
}

}  // namespace cradle

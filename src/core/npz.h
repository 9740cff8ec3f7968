// NumPy .npz files (a zip of .npy arrays), written the way np.savez / np.savez_compressed do so
// that numpy.load reads them without pickle, and read back for round trips and tests.
#pragma once

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <span>
#include <string>
#include <vector>

namespace cradle {

// Collects named arrays and writes them as one .npz on close() (the zip container through libzip,
// zip64 when large). Each add() encodes its array as .npy bytes at once; close() compresses. The
// zip is byte-for-byte deterministic: members in add() order, a fixed 1980-01-01 timestamp.
class NpzWriter {
 public:
  // compress: deflate members as np.savez_compressed does; false: store all, as np.savez does.
  explicit NpzWriter(std::filesystem::path file, bool compress = true);
  NpzWriter(const NpzWriter&) = delete;
  NpzWriter& operator=(const NpzWriter&) = delete;
  // Closes if still open, swallowing any error: call close() to learn about write failures.
  ~NpzWriter();

  // Typed arrays in C order; an empty shape is a 0-d array of one element. std::invalid_argument
  // when the shape product differs from data.size(), on more than 32 dimensions, an empty or
  // repeated name, or a closed writer.
  void add(const std::string& name, std::span<const double> data, std::vector<std::size_t> shape);
  void add(const std::string& name, std::span<const float> data, std::vector<std::size_t> shape);
  void add(const std::string& name, std::span<const std::int32_t> data,
           std::vector<std::size_t> shape);
  void add(const std::string& name, std::span<const std::int64_t> data,
           std::vector<std::size_t> shape);
  void add(const std::string& name, std::span<const std::uint8_t> data,
           std::vector<std::size_t> shape);
  // A 1-D array of byte strings, dtype 'S<longest>' (at least S1), e.g. one JSON text per step.
  // As in numpy, trailing NUL bytes of a value do not survive the round trip.
  void add_strings(const std::string& name, const std::vector<std::string>& values);

  // Writes the file atomically: a temp file in the same folder (parents created), then rename.
  // Throws UserError with a one-line message if it cannot; no partial file is left. The writer
  // is closed afterwards either way; later calls do nothing.
  void close();

 private:
  struct Member {
    std::string name;               // zip member name, "<array name>.npy"
    std::vector<std::uint8_t> npy;  // the .npy bytes
  };

  // Encodes one array (descr like "<f8", raw little-endian bytes) as a member.
  void add_raw(const std::string& name, const std::string& descr, std::vector<std::size_t> shape,
               std::size_t count, const void* data, std::size_t bytes);

  std::filesystem::path file_;
  bool compress_;
  bool closed_ = false;
  std::vector<Member> members_;
};

// One array read from a .npy member.
struct NpyArray {
  std::string descr;                // numpy dtype descr, e.g. "<f8", "|u1", "|S12"
  std::vector<std::size_t> shape;   // empty for a 0-d array
  std::vector<std::uint8_t> bytes;  // C-order element bytes, as stored

  std::size_t item_size() const;  // bytes per element, from descr
  std::size_t count() const;      // product of shape
  // The elements as T; std::invalid_argument unless descr is T's ("<f8" for double etc.).
  template <typename T>
  std::vector<T> values() const;
  // The elements of an "|S<n>" array, trailing NULs stripped; std::invalid_argument otherwise.
  std::vector<std::string> strings() const;
};

// Reads every member of an .npz (stored or deflated, as numpy writes them) keyed by array name
// (".npy" stripped). Throws UserError naming the file on anything malformed or unsupported
// (Fortran order, structured dtypes, a bad crc).
std::map<std::string, NpyArray> read_npz(const std::filesystem::path& file);

extern template std::vector<double> NpyArray::values<double>() const;
extern template std::vector<float> NpyArray::values<float>() const;
extern template std::vector<std::int32_t> NpyArray::values<std::int32_t>() const;
extern template std::vector<std::int64_t> NpyArray::values<std::int64_t>() const;
extern template std::vector<std::uint8_t> NpyArray::values<std::uint8_t>() const;

}  // namespace cradle

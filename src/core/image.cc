#include "core/image.h"

#include <stb_image_write.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <string>
#include <system_error>

#include "core/error.h"

namespace cradle {

std::vector<std::uint8_t> encode_png(const Image& image) {
  std::vector<std::uint8_t> png;
  // stb hands the encoded stream over in one or more chunks.
  const auto append = [](void* context, void* data, int size) {
    auto* out = static_cast<std::vector<std::uint8_t>*>(context);
    const auto* bytes = static_cast<const std::uint8_t*>(data);
    out->insert(out->end(), bytes, bytes + size);
  };
  stbi_write_png_to_func(append, &png, image.width, image.height, 3, image.rgb.data(),
                         image.width * 3);
  return png;
}

void write_png(const Image& image, const std::filesystem::path& file) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgb.size() != 3 * static_cast<std::size_t>(image.width) * image.height) {
    throw UserError("cannot write image '" + file.string() + "': it is " +
                    std::to_string(image.width) + "x" + std::to_string(image.height) + " with " +
                    std::to_string(image.rgb.size()) + " bytes; expected a non-empty RGB image");
  }
  const std::vector<std::uint8_t> png = encode_png(image);
  if (png.empty()) throw UserError("cannot encode image '" + file.string() + "' as PNG");
  std::error_code ec;
  if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path(), ec);
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  if (!out) {
    const std::string why = ec ? ec.message() : std::strerror(errno);
    throw UserError("cannot write image '" + file.string() + "': " + why +
                    "; expected a writable file path");
  }
  out.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  out.close();
  if (!out) throw UserError("cannot write image '" + file.string() + "': writing failed");
}

}  // namespace cradle

// An RGB image (textures, camera frames, video frames) and its PNG encoding (stb_image_write).
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

namespace cradle {

struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;  // row-major, row 0 at the top, 3 bytes per pixel
};

// PNG bytes of an image (empty if stb cannot encode it).
std::vector<std::uint8_t> encode_png(const Image& image);

// Writes an image as PNG, creating missing parent folders; throws UserError if it cannot.
void write_png(const Image& image, const std::filesystem::path& file);

}  // namespace cradle

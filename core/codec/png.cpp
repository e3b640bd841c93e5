#include "fluidcast/codec/png.h"

#include <png.h>

#include <cstdint>
#include <stdexcept>
#include <string>

namespace fluidcast::codec {

void write_png(const std::filesystem::path& path, const ImageRgba& image) {
  png_image info{};
  info.version = PNG_IMAGE_VERSION;
  info.width = static_cast<png_uint_32>(image.width);
  info.height = static_cast<png_uint_32>(image.height);
  info.format = PNG_FORMAT_RGBA;
  if (!png_image_write_to_file(&info, path.c_str(), 0, image.pixels.data(), 0, nullptr)) {
    throw std::runtime_error("png: cannot write " + path.string() + ": " + info.message);
  }
}

ImageRgba read_png(const std::filesystem::path& path) {
  png_image info{};
  info.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&info, path.c_str())) {
    throw std::runtime_error("png: cannot read " + path.string() + ": " + info.message);
  }
  info.format = PNG_FORMAT_RGBA;
  if (std::uint64_t{info.width} * info.height > (std::uint64_t{1} << 28)) {
    png_image_free(&info);
    throw std::runtime_error("png: " + path.string() + " is " + std::to_string(info.width) + "×" +
                             std::to_string(info.height) + ", over 2^28 pixels");
  }
  ImageRgba image(static_cast<int>(info.width), static_cast<int>(info.height));
  if (!png_image_finish_read(&info, nullptr, image.pixels.data(), 0, nullptr)) {
    const std::string message = info.message;
    png_image_free(&info);
    throw std::runtime_error("png: cannot decode " + path.string() + ": " + message);
  }
  return image;
}

}  // namespace fluidcast::codec

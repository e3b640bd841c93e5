// PNG files, for tests (golden images) and tools: lossless, 8-bit RGBA.
#pragma once

#include <filesystem>

#include "fluidcast/codec/image.h"

namespace fluidcast::codec {

// Both throw std::runtime_error naming the file and what went wrong.
void write_png(const std::filesystem::path& path, const ImageRgba& image);
ImageRgba read_png(const std::filesystem::path& path);

}  // namespace fluidcast::codec

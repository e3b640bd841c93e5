// An 8-bit RGBA image in host memory, rows top to bottom: what the renderer reads back and what
// the codecs take and give.
#pragma once

#include <cstdint>
#include <vector>

namespace fluidcast::codec {

struct ImageRgba {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;  // width · height · 4 bytes

  ImageRgba() = default;
  // Throws std::invalid_argument for a size that is not positive or too large (over 2^28 pixels).
  ImageRgba(int w, int h);

  std::uint8_t* pixel(int x, int y) {
    return pixels.data() + 4 * (static_cast<std::size_t>(y) * width + x);
  }
  const std::uint8_t* pixel(int x, int y) const {
    return pixels.data() + 4 * (static_cast<std::size_t>(y) * width + x);
  }
};

// Peak signal-to-noise ratio over the RGB channels, in dB (infinity for identical images).
// Throws std::invalid_argument for images of different sizes.
double psnr(const ImageRgba& a, const ImageRgba& b);

}  // namespace fluidcast::codec

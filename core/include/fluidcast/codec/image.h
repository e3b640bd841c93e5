// Images in host memory, rows top to bottom: what the renderer reads back and what the codecs take
// and give. RGBA for anything that looks at pixels; the YCbCr planes of a JPEG for streaming,
// where the GPU has done the colour conversion and the subsampling already.
#pragma once

#include <cstdint>
#include <variant>
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

// The planes a baseline JPEG holds: Y at full size, Cb and Cr at half size each way (4:2:0,
// rounded up), full-range BT.601 as JFIF defines it. The renderer writes them four bytes at a time
// from blocks of 8×2 pixels, so rows are padded to luma_stride() bytes (a multiple of 8) and the
// luma plane to an even number of rows; what lies beyond width and height repeats the edge.
struct ImageYuv420 {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> bytes;  // Y rows, then Cb rows, then Cr rows

  ImageYuv420() = default;
  // Throws std::invalid_argument as ImageRgba does.
  ImageYuv420(int w, int h);

  static std::size_t size_for(int w, int h);
  int luma_stride() const { return (width + 7) / 8 * 8; }
  int luma_rows() const { return 2 * chroma_rows(); }
  int chroma_stride() const { return luma_stride() / 2; }
  int chroma_rows() const { return (height + 1) / 2; }
  // 0: Y, 1: Cb, 2: Cr.
  const std::uint8_t* plane(int k) const;
};

// A frame as the renderer reads it back.
using Image = std::variant<ImageRgba, ImageYuv420>;
inline int width_of(const Image& image) {
  return std::visit([](const auto& i) { return i.width; }, image);
}
inline int height_of(const Image& image) {
  return std::visit([](const auto& i) { return i.height; }, image);
}

// Peak signal-to-noise ratio over the RGB channels, in dB (infinity for identical images).
// Throws std::invalid_argument for images of different sizes.
double psnr(const ImageRgba& a, const ImageRgba& b);

}  // namespace fluidcast::codec

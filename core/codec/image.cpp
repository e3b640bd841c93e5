#include "fluidcast/codec/image.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace fluidcast::codec {

namespace {

void check_size(int w, int h) {
  if (w <= 0 || h <= 0 || static_cast<double>(w) * h > double(1 << 28)) {
    throw std::invalid_argument("image: size " + std::to_string(w) + "×" + std::to_string(h) +
                                " must be positive and at most 2^28 pixels");
  }
}

}  // namespace

ImageRgba::ImageRgba(int w, int h) : width(w), height(h) {
  check_size(w, h);
  pixels.assign(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) * 4, 0);
}

ImageYuv420::ImageYuv420(int w, int h) : width(w), height(h) {
  check_size(w, h);
  bytes.assign(size_for(w, h), 0);
}

std::size_t ImageYuv420::size_for(int w, int h) {
  ImageYuv420 shape;
  shape.width = w;
  shape.height = h;
  const auto luma = static_cast<std::size_t>(shape.luma_stride()) * shape.luma_rows();
  const auto chroma = static_cast<std::size_t>(shape.chroma_stride()) * shape.chroma_rows();
  return luma + 2 * chroma;
}

const std::uint8_t* ImageYuv420::plane(int k) const {
  const auto luma = static_cast<std::size_t>(luma_stride()) * luma_rows();
  const auto chroma = static_cast<std::size_t>(chroma_stride()) * chroma_rows();
  return bytes.data() + (k == 0 ? 0 : luma + static_cast<std::size_t>(k - 1) * chroma);
}

double psnr(const ImageRgba& a, const ImageRgba& b) {
  if (a.width != b.width || a.height != b.height) {
    throw std::invalid_argument("psnr: images of different sizes");
  }
  double squared = 0.0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < a.pixels.size(); i += 4) {
    for (int c = 0; c < 3; ++c) {
      const double d = double(a.pixels[i + c]) - double(b.pixels[i + c]);
      squared += d * d;
      ++count;
    }
  }
  if (squared == 0.0) return std::numeric_limits<double>::infinity();
  return 10.0 * std::log10(255.0 * 255.0 / (squared / static_cast<double>(count)));
}

}  // namespace fluidcast::codec

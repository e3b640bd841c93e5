#include "fluidcast/codec/jpeg.h"

#include <turbojpeg.h>

#include <stdexcept>
#include <string>

namespace fluidcast::codec {
namespace {

void* make_handle(bool compress) {
  tjhandle handle = compress ? tjInitCompress() : tjInitDecompress();
  if (!handle) {
    throw std::runtime_error(std::string("TurboJPEG: cannot create a handle: ") +
                             tjGetErrorStr2(nullptr));
  }
  return handle;
}

int subsampling_of(ChromaSubsampling s) {
  switch (s) {
    case ChromaSubsampling::s444:
      return TJSAMP_444;
    case ChromaSubsampling::s422:
      return TJSAMP_422;
    case ChromaSubsampling::s420:
      return TJSAMP_420;
  }
  throw std::invalid_argument("jpeg: unknown chroma subsampling");
}

}  // namespace

JpegEncoder::JpegEncoder() : handle_(make_handle(true)) {}
JpegEncoder::~JpegEncoder() { tjDestroy(handle_); }

std::vector<std::uint8_t> JpegEncoder::encode(const ImageRgba& image, const JpegOptions& options) {
  if (image.width <= 0 || image.height <= 0 ||
      image.pixels.size() != static_cast<std::size_t>(image.width) * image.height * 4) {
    throw std::invalid_argument("jpeg: the image is empty or its pixels do not match its size");
  }
  if (options.quality < 1 || options.quality > 100) {
    throw std::invalid_argument("jpeg: quality " + std::to_string(options.quality) +
                                " is outside 1–100");
  }
  unsigned char* out = nullptr;
  unsigned long size = 0;
  const int status =
      tjCompress2(handle_, image.pixels.data(), image.width, 0, image.height, TJPF_RGBA, &out,
                  &size, subsampling_of(options.subsampling), options.quality, 0);
  if (status != 0) {
    tjFree(out);
    throw std::runtime_error(std::string("jpeg: encoding failed: ") + tjGetErrorStr2(handle_));
  }
  std::vector<std::uint8_t> jpeg(out, out + size);
  tjFree(out);
  return jpeg;
}

JpegDecoder::JpegDecoder() : handle_(make_handle(false)) {}
JpegDecoder::~JpegDecoder() { tjDestroy(handle_); }

ImageRgba JpegDecoder::decode(std::span<const std::uint8_t> jpeg) {
  int width = 0, height = 0, subsampling = 0, colorspace = 0;
  if (tjDecompressHeader3(handle_, jpeg.data(), static_cast<unsigned long>(jpeg.size()), &width,
                          &height, &subsampling, &colorspace) != 0) {
    throw std::runtime_error(std::string("jpeg: not a JPEG image: ") + tjGetErrorStr2(handle_));
  }
  ImageRgba image(width, height);
  if (tjDecompress2(handle_, jpeg.data(), static_cast<unsigned long>(jpeg.size()),
                    image.pixels.data(), width, 0, height, TJPF_RGBA, TJFLAG_FASTDCT) != 0) {
    throw std::runtime_error(std::string("jpeg: decoding failed: ") + tjGetErrorStr2(handle_));
  }
  return image;
}

std::vector<std::uint8_t> encode_jpeg(const ImageRgba& image, const JpegOptions& options) {
  thread_local JpegEncoder encoder;
  return encoder.encode(image, options);
}

ImageRgba decode_jpeg(std::span<const std::uint8_t> jpeg) {
  thread_local JpegDecoder decoder;
  return decoder.decode(jpeg);
}

}  // namespace fluidcast::codec

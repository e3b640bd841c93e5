#include "fluidcast/codec/jpeg.h"

#include <turbojpeg.h>

#include <stdexcept>
#include <string>
#include <utility>

#include "fluidcast/codec/jpeg_strips.h"

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

void check_quality(const JpegOptions& options) {
  if (options.quality < 1 || options.quality > 100) {
    throw std::invalid_argument("jpeg: quality " + std::to_string(options.quality) +
                                " is outside 1–100");
  }
}

// A strip starts on a block row (jpeg_strips.h) and lies within the image.
void check_rows(int height, int first_row, int rows) {
  if (first_row < 0 || rows <= 0 || first_row > height - rows ||
      first_row % kJpegStripRowMultiple != 0) {
    throw std::invalid_argument("jpeg: rows " + std::to_string(first_row) + " to " +
                                std::to_string(first_row + rows) + " are not a strip of an image " +
                                std::to_string(height) + " rows high");
  }
}

// TurboJPEG's output, copied out and freed.
std::vector<std::uint8_t> take_output(void* handle, int status, unsigned char* out,
                                      unsigned long size) {
  if (status != 0) {
    tjFree(out);
    throw std::runtime_error(std::string("jpeg: encoding failed: ") + tjGetErrorStr2(handle));
  }
  std::vector<std::uint8_t> jpeg(out, out + size);
  tjFree(out);
  return jpeg;
}

}  // namespace

JpegEncoder::JpegEncoder() : handle_(make_handle(true)) {}
JpegEncoder::~JpegEncoder() { tjDestroy(handle_); }

std::vector<std::uint8_t> JpegEncoder::encode(const ImageRgba& image, const JpegOptions& options) {
  return encode_rows(image, 0, image.height, options);
}

std::vector<std::uint8_t> JpegEncoder::encode(const ImageYuv420& image,
                                              const JpegOptions& options) {
  return encode_rows(image, 0, image.height, options);
}

std::vector<std::uint8_t> JpegEncoder::encode_rows(const ImageRgba& image, int first_row, int rows,
                                                   const JpegOptions& options) {
  if (image.width <= 0 || image.height <= 0 ||
      image.pixels.size() != static_cast<std::size_t>(image.width) * image.height * 4) {
    throw std::invalid_argument("jpeg: the image is empty or its pixels do not match its size");
  }
  check_rows(image.height, first_row, rows);
  check_quality(options);
  unsigned char* out = nullptr;
  unsigned long size = 0;
  const int status =
      tjCompress2(handle_, image.pixel(0, first_row), image.width, 0, rows, TJPF_RGBA, &out, &size,
                  subsampling_of(options.subsampling), options.quality, 0);
  return take_output(handle_, status, out, size);
}

std::vector<std::uint8_t> JpegEncoder::encode_rows(const ImageYuv420& image, int first_row,
                                                   int rows, const JpegOptions& options) {
  if (image.width <= 0 || image.height <= 0 ||
      image.bytes.size() != ImageYuv420::size_for(image.width, image.height)) {
    throw std::invalid_argument("jpeg: the planes are empty or do not match their size");
  }
  check_rows(image.height, first_row, rows);
  check_quality(options);
  if (options.subsampling != ChromaSubsampling::s420) {
    throw std::invalid_argument("jpeg: YCbCr 4:2:0 planes encode only with 4:2:0 subsampling");
  }
  const std::size_t luma_offset = static_cast<std::size_t>(first_row) * image.luma_stride();
  const std::size_t chroma_offset = static_cast<std::size_t>(first_row / 2) * image.chroma_stride();
  const unsigned char* planes[3] = {image.plane(0) + luma_offset, image.plane(1) + chroma_offset,
                                    image.plane(2) + chroma_offset};
  const int strides[3] = {image.luma_stride(), image.chroma_stride(), image.chroma_stride()};
  unsigned char* out = nullptr;
  unsigned long size = 0;
  const int status = tjCompressFromYUVPlanes(handle_, planes, image.width, strides, rows,
                                             TJSAMP_420, &out, &size, options.quality, 0);
  return take_output(handle_, status, out, size);
}

JpegDecoder::JpegDecoder() : handle_(make_handle(false)) {}
JpegDecoder::~JpegDecoder() { tjDestroy(handle_); }

void JpegDecoder::replace_handle_and_throw(const std::string& what) {
  const std::string message = what + tjGetErrorStr2(handle_);
  void* fresh = make_handle(false);  // first: a throw here leaves the old handle, still ours
  tjDestroy(std::exchange(handle_, fresh));
  throw std::runtime_error(message);
}

ImageRgba JpegDecoder::decode(std::span<const std::uint8_t> jpeg) {
  int width = 0, height = 0, subsampling = 0, colorspace = 0;
  if (tjDecompressHeader3(handle_, jpeg.data(), static_cast<unsigned long>(jpeg.size()), &width,
                          &height, &subsampling, &colorspace) != 0) {
    replace_handle_and_throw("jpeg: not a JPEG image: ");
  }
  ImageRgba image(width, height);
  if (tjDecompress2(handle_, jpeg.data(), static_cast<unsigned long>(jpeg.size()),
                    image.pixels.data(), width, 0, height, TJPF_RGBA, TJFLAG_FASTDCT) != 0) {
    replace_handle_and_throw("jpeg: decoding failed: ");
  }
  return image;
}

namespace {
JpegEncoder& this_threads_encoder() {
  thread_local JpegEncoder encoder;
  return encoder;
}
}  // namespace

std::vector<std::uint8_t> encode_jpeg(const Image& image, const JpegOptions& options) {
  return std::visit(
      [&](const auto& pixels) { return this_threads_encoder().encode(pixels, options); }, image);
}

std::vector<std::uint8_t> encode_jpeg_rows(const Image& image, int first_row, int rows,
                                           const JpegOptions& options) {
  return std::visit(
      [&](const auto& pixels) {
        return this_threads_encoder().encode_rows(pixels, first_row, rows, options);
      },
      image);
}

ImageRgba decode_jpeg(std::span<const std::uint8_t> jpeg) {
  thread_local JpegDecoder decoder;
  return decoder.decode(jpeg);
}

}  // namespace fluidcast::codec

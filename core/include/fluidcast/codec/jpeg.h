// JPEG through TurboJPEG. Creating a TurboJPEG handle costs about 2 ms, so each thread keeps one
// encoder and one decoder and reuses them (encode_jpeg / decode_jpeg); a JpegEncoder object is
// for a thread that wants its own.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "fluidcast/codec/image.h"

namespace fluidcast::codec {

enum class ChromaSubsampling { s444, s422, s420 };

struct JpegOptions {
  int quality = 80;                                         // 1–100
  ChromaSubsampling subsampling = ChromaSubsampling::s420;  // 4:2:0 encodes ~1.7× faster than 4:4:4
};

class JpegEncoder {
 public:
  JpegEncoder();
  ~JpegEncoder();
  JpegEncoder(const JpegEncoder&) = delete;
  JpegEncoder& operator=(const JpegEncoder&) = delete;

  // Throws std::invalid_argument for an empty image or a quality outside 1–100, and for planes
  // with any subsampling but theirs (4:2:0).
  std::vector<std::uint8_t> encode(const ImageRgba& image, const JpegOptions& options);
  std::vector<std::uint8_t> encode(const ImageYuv420& image, const JpegOptions& options);
  // Rows [first_row, first_row + rows) alone, as a JPEG of their own (a strip, jpeg_strips.h);
  // first_row a multiple of kJpegStripRowMultiple. Throws as encode does, and for rows outside
  // the image.
  std::vector<std::uint8_t> encode_rows(const ImageRgba& image, int first_row, int rows,
                                        const JpegOptions& options);
  std::vector<std::uint8_t> encode_rows(const ImageYuv420& image, int first_row, int rows,
                                        const JpegOptions& options);

 private:
  void* handle_;
};

class JpegDecoder {
 public:
  JpegDecoder();
  ~JpegDecoder();
  JpegDecoder(const JpegDecoder&) = delete;
  JpegDecoder& operator=(const JpegDecoder&) = delete;

  // Throws std::runtime_error naming what TurboJPEG found wrong for data that is not a JPEG.
  ImageRgba decode(std::span<const std::uint8_t> jpeg);

 private:
  // After a failed decode TurboJPEG 2.1's handle fails every later one ("Bogus Huffman table
  // definition" for a good JPEG): a failure gets a fresh handle, so that one bad frame costs
  // only itself.
  [[noreturn]] void replace_handle_and_throw(const std::string& what);

  void* handle_;
};

// With this thread's own encoder or decoder.
std::vector<std::uint8_t> encode_jpeg(const Image& image, const JpegOptions& options = {});
std::vector<std::uint8_t> encode_jpeg_rows(const Image& image, int first_row, int rows,
                                           const JpegOptions& options);
ImageRgba decode_jpeg(std::span<const std::uint8_t> jpeg);

}  // namespace fluidcast::codec

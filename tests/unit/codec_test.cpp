// JPEG and PNG: round trips, quality, sizes, bad input, strips, and the encoder pool.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>

#include "fluidcast/codec/jpeg.h"
#include "fluidcast/codec/jpeg_encoder_pool.h"
#include "fluidcast/codec/jpeg_strips.h"
#include "fluidcast/codec/png.h"

namespace fluidcast::codec {
namespace {

// Something like a rendered frame: smooth gradients, a disc with an anti-aliased edge (about two
// pixels wide, as a rendered edge is), a few one-pixel bright lines.
ImageRgba test_picture(int width, int height) {
  ImageRgba image(width, height);
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const double u = double(x) / width, v = double(y) / height;
      const double edge = (0.25 - std::hypot(u - 0.5, v - 0.55)) * width / 2.0;
      const double disc = std::clamp(edge + 0.5, 0.0, 1.0);
      std::uint8_t* p = image.pixel(x, y);
      p[0] = static_cast<std::uint8_t>(40 + 120 * v + 60 * disc);
      p[1] = static_cast<std::uint8_t>(80 + 100 * u * (1 - disc));
      p[2] = static_cast<std::uint8_t>(160 + 90 * disc * (1 - v));
      if (y % 64 == 0) p[0] = p[1] = p[2] = 250;
      p[3] = 255;
    }
  }
  return image;
}

// 4:4:4 keeps 38 dB at quality 90. 4:2:0 halves the colour resolution, which costs the one-pixel
// lines of this picture (measured 36.9 dB): it is held to 35 dB.
TEST(Jpeg, RoundTripAtQuality90IsAbove38Decibels) {
  const ImageRgba picture = test_picture(640, 360);
  for (auto subsampling : {ChromaSubsampling::s444, ChromaSubsampling::s420}) {
    const double floor = subsampling == ChromaSubsampling::s444 ? 38.0 : 35.0;
    const auto jpeg = encode_jpeg(picture, {90, subsampling});
    const ImageRgba back = decode_jpeg(jpeg);
    ASSERT_EQ(back.width, 640);
    ASSERT_EQ(back.height, 360);
    const double db = psnr(picture, back);
    std::printf("quality 90, %s: %zu bytes, %.1f dB\n",
                subsampling == ChromaSubsampling::s444 ? "4:4:4" : "4:2:0", jpeg.size(), db);
    EXPECT_GE(db, floor);
  }
}

TEST(Jpeg, LowerQualityIsSmallerAndWorse) {
  const ImageRgba picture = test_picture(320, 240);
  const auto high = encode_jpeg(picture, {95}), low = encode_jpeg(picture, {20});
  EXPECT_LT(low.size(), high.size());
  EXPECT_LT(psnr(picture, decode_jpeg(low)), psnr(picture, decode_jpeg(high)));
}

TEST(Jpeg, OneByOneAndOddSizes) {
  for (auto [w, h] : {std::pair{1, 1}, {3, 7}, {641, 359}}) {
    const ImageRgba picture = test_picture(w, h);
    const ImageRgba back = decode_jpeg(encode_jpeg(picture, {90}));
    EXPECT_EQ(back.width, w);
    EXPECT_EQ(back.height, h);
  }
}

TEST(Jpeg, BadInputIsRefusedWithAReason) {
  const ImageRgba picture = test_picture(8, 8);
  EXPECT_THROW(encode_jpeg(picture, {0}), std::invalid_argument);
  EXPECT_THROW(encode_jpeg(picture, {101}), std::invalid_argument);
  EXPECT_THROW(encode_jpeg(ImageRgba{}, {}), std::invalid_argument);
  const std::vector<std::uint8_t> not_jpeg = {1, 2, 3, 4, 5};
  try {
    decode_jpeg(not_jpeg);
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("not a JPEG"), std::string::npos) << e.what();
  }
  auto truncated = encode_jpeg(picture, {});
  truncated.resize(truncated.size() / 3);
  EXPECT_THROW(decode_jpeg(truncated), std::runtime_error);
  // One bad frame costs only itself: this thread's decoder decodes the next good one.
  EXPECT_EQ(decode_jpeg(encode_jpeg(picture, {})).width, 8);
  EXPECT_THROW(ImageRgba(0, 5), std::invalid_argument);
  ImageRgba short_of_pixels = picture;
  short_of_pixels.pixels.pop_back();
  EXPECT_THROW(encode_jpeg(short_of_pixels, {}), std::invalid_argument);
  // Rows within the image only: one row past the end or before the first (each would read outside
  // the pixels), or none, are refused.
  const ImageRgba tall = test_picture(8, 64);
  EXPECT_NO_THROW(encode_jpeg_rows(tall, 48, 16, {}));
  EXPECT_THROW(encode_jpeg_rows(tall, 48, 17, {}), std::invalid_argument);
  EXPECT_THROW(encode_jpeg_rows(tall, 16, 0, {}), std::invalid_argument);
  EXPECT_THROW(encode_jpeg_rows(tall, -16, 16, {}), std::invalid_argument);
}

// The chroma subsampling asked for is the one in the frame header: the luma's sampling factors
// (horizontal, vertical), each chroma component's one by one.
TEST(Jpeg, EachSubsamplingIsTheOneAskedFor) {
  // SOF0: marker, length, precision, height, width, 3 components of (id, factors, table).
  const auto luma_factors = [](const std::vector<std::uint8_t>& jpeg) {
    for (std::size_t at = 2; at + 17 < jpeg.size(); ++at) {
      if (jpeg[at] == 0xFF && jpeg[at + 1] == 0xC0) {
        EXPECT_EQ(jpeg[at + 14], 0x11);  // Cb
        EXPECT_EQ(jpeg[at + 17], 0x11);  // Cr
        return int(jpeg[at + 11]);
      }
    }
    return 0;
  };
  const ImageRgba picture = test_picture(32, 32);
  EXPECT_EQ(luma_factors(encode_jpeg(picture, {80, ChromaSubsampling::s444})), 0x11);
  EXPECT_EQ(luma_factors(encode_jpeg(picture, {80, ChromaSubsampling::s422})), 0x21);
  EXPECT_EQ(luma_factors(encode_jpeg(picture, {80, ChromaSubsampling::s420})), 0x22);
}

TEST(Jpeg, PlanesOfTheWrongSizeOrSubsamplingAreRefused) {
  ImageYuv420 planes(9, 5);
  EXPECT_EQ(planes.luma_stride(), 16);
  EXPECT_EQ(planes.luma_rows(), 6);
  EXPECT_EQ(planes.bytes.size(), std::size_t{16 * 6 + 2 * 8 * 3});
  EXPECT_FALSE(encode_jpeg(planes, {80}).empty());
  EXPECT_THROW(encode_jpeg(planes, {80, ChromaSubsampling::s444}), std::invalid_argument);
  planes.bytes.pop_back();
  EXPECT_THROW(encode_jpeg(planes, {80}), std::invalid_argument);
  EXPECT_THROW(ImageYuv420(0, 5), std::invalid_argument);
}

TEST(Png, RoundTripIsExact) {
  const ImageRgba picture = test_picture(97, 55);
  const auto path = std::filesystem::temp_directory_path() / "fluidcast_codec_test.png";
  write_png(path, picture);
  const ImageRgba back = read_png(path);
  std::filesystem::remove(path);
  EXPECT_EQ(back.width, 97);
  EXPECT_EQ(back.pixels, picture.pixels);
  EXPECT_THROW(read_png("/nonexistent/frame.png"), std::runtime_error);
}

// Planes as the GPU writes them, from a pattern with edges in every block.
ImageYuv420 test_planes(int width, int height) {
  ImageYuv420 planes(width, height);
  for (std::size_t i = 0; i < planes.bytes.size(); ++i) {
    planes.bytes[i] = static_cast<std::uint8_t>((i * 37 + i / 97 * 11) % 251);
  }
  return planes;
}

std::vector<std::vector<std::uint8_t>> strips_of(const Image& image, int strip_rows,
                                                 const JpegOptions& options) {
  std::vector<std::vector<std::uint8_t>> strips;
  const int height = height_of(image);
  for (int first = 0; first < height; first += strip_rows) {
    strips.push_back(encode_jpeg_rows(image, first, std::min(strip_rows, height - first), options));
  }
  return strips;
}

bool has_restart_markers(const std::vector<std::uint8_t>& jpeg) {
  for (std::size_t i = 0; i + 1 < jpeg.size(); ++i) {
    if (jpeg[i] == 0xFF && jpeg[i + 1] == 0xDD) return true;
  }
  return false;
}

// The strips' scans joined decode to exactly the pixels of one encode of the whole image: odd
// sizes, a last strip shorter than the rest, RGBA at 4:2:0 and 4:4:4, and the GPU's planes.
TEST(JpegStrips, JoinedStripsDecodeToTheWholeEncodesPixels) {
  struct Case {
    Image image;
    JpegOptions options;
    int strip_rows;
  };
  const Case cases[] = {{test_picture(101, 57), {85}, 16},
                        {test_picture(101, 57), {85, ChromaSubsampling::s444}, 32},
                        {test_picture(640, 360), {80}, jpeg_strip_rows(360, 3)},
                        {test_planes(173, 75), {80}, 16},
                        {test_planes(1920, 1080), {80}, jpeg_strip_rows(1080, 8)}};
  for (const Case& c : cases) {
    SCOPED_TRACE(std::to_string(width_of(c.image)) + "x" + std::to_string(height_of(c.image)) +
                 " in strips of " + std::to_string(c.strip_rows));
    const std::vector<std::uint8_t> joined =
        join_jpeg_strips(strips_of(c.image, c.strip_rows, c.options), c.strip_rows);
    EXPECT_TRUE(has_restart_markers(joined));
    const ImageRgba whole = decode_jpeg(encode_jpeg(c.image, c.options));
    const ImageRgba parts = decode_jpeg(joined);
    ASSERT_EQ(parts.width, whole.width);
    ASSERT_EQ(parts.height, whole.height);
    EXPECT_EQ(parts.pixels, whole.pixels);
  }
  EXPECT_EQ(jpeg_strip_rows(1080, 8), 144);  // a multiple of 16: 7 strips of 144, one of 72
  EXPECT_EQ(jpeg_strip_rows(10, 4), 16);
  // At most the strips asked for: 33 rows in two strips are 32 and 1, not three of 16.
  EXPECT_EQ(jpeg_strip_rows(33, 2), 32);
  EXPECT_EQ(jpeg_strip_rows(16, 1), 16);
}

TEST(JpegStrips, StripsThatDoNotFitTogetherAreRefused) {
  const ImageRgba picture = test_picture(96, 64);
  std::vector<std::vector<std::uint8_t>> strips = strips_of(picture, 32, {80});
  EXPECT_THROW(join_jpeg_strips(strips, 16), std::invalid_argument);  // not the strips' height
  std::vector<std::vector<std::uint8_t>> other_quality = strips;
  other_quality[1] = encode_jpeg_rows(picture, 32, 32, {60});
  EXPECT_THROW(join_jpeg_strips(other_quality, 32), std::invalid_argument);
  std::vector<std::vector<std::uint8_t>> other_width = strips;
  other_width[1] = encode_jpeg_rows(test_picture(80, 64), 32, 32, {80});
  EXPECT_THROW(join_jpeg_strips(other_width, 32), std::invalid_argument);
  std::vector<std::vector<std::uint8_t>> last_too_tall = strips_of(picture, 16, {80});
  last_too_tall.back() = encode_jpeg_rows(picture, 32, 32, {80});
  last_too_tall.erase(last_too_tall.begin() + 2);
  EXPECT_THROW(join_jpeg_strips(last_too_tall, 16), std::invalid_argument);
  std::vector<std::vector<std::uint8_t>> damaged = strips;
  damaged[1].resize(10);
  EXPECT_THROW(join_jpeg_strips(damaged, 32), std::invalid_argument);
  EXPECT_THROW(encode_jpeg_rows(picture, 8, 16, {80}), std::invalid_argument);   // not a block row
  EXPECT_THROW(encode_jpeg_rows(picture, 48, 32, {80}), std::invalid_argument);  // past the end
}

// Each way strips can fail to make one JPEG is refused, so that the frame is encoded whole instead.
TEST(JpegStrips, StripsThatWouldJoinWrongAreRefused) {
  const JpegOptions fine{80, ChromaSubsampling::s444};  // blocks of 8 rows
  const ImageRgba picture = test_picture(96, 48);
  // A strip before the last shorter than the rest: the restart intervals would fall mid-strip.
  std::vector<std::vector<std::uint8_t>> short_middle = {encode_jpeg_rows(picture, 0, 16, fine),
                                                         encode_jpeg_rows(picture, 16, 8, fine),
                                                         encode_jpeg_rows(picture, 32, 16, fine)};
  EXPECT_THROW(join_jpeg_strips(short_middle, 16), std::invalid_argument);
  // Strips that are not a whole number of blocks high, though each a JPEG of its own.
  const std::vector<std::uint8_t> twelve = encode_jpeg(test_picture(96, 12), fine);
  EXPECT_THROW(join_jpeg_strips({twelve, twelve}, 12), std::invalid_argument);
  // More blocks in a strip than a restart interval counts (65535): 1025 × 64 here.
  const std::vector<std::uint8_t> wide = encode_jpeg(test_picture(8200, 512), fine);
  try {
    join_jpeg_strips({wide, wide}, 512);
    ADD_FAILURE() << "joined strips of 65600 blocks";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("restart interval"), std::string::npos) << e.what();
  }
  // More rows than a JPEG holds (65500): seven strips of 8192 and a last one to 65500 join, one
  // row more does not.
  const std::vector<std::uint8_t> strip = encode_jpeg(test_picture(8, 8192), fine);
  std::vector<std::vector<std::uint8_t>> strips(7, strip);
  strips.push_back(encode_jpeg(test_picture(8, 65500 - 7 * 8192), fine));
  EXPECT_NO_THROW(join_jpeg_strips(strips, 8192));
  strips.back() = encode_jpeg(test_picture(8, 65501 - 7 * 8192), fine);
  EXPECT_THROW(join_jpeg_strips(strips, 8192), std::invalid_argument);
}

TEST(JpegEncoderPool, EncodesATallFrameInStripsOnSeveralThreads) {
  JpegEncoderPool pool(3);
  const ImageRgba picture = test_picture(320, 3 * JpegEncoderPool::kLeastStripRows + 5);
  const std::vector<std::uint8_t> jpeg = pool.encode(picture, {80}).get();
  EXPECT_TRUE(has_restart_markers(jpeg));
  EXPECT_EQ(decode_jpeg(jpeg).pixels, decode_jpeg(encode_jpeg(picture, {80})).pixels);
  auto bad = pool.encode(picture, {101});
  EXPECT_THROW(bad.get(), std::invalid_argument);
}

// TurboJPEG reads TJ_RESTART (and TJ_OPTIMIZE, ...) from the environment: strips it marks that
// way cannot be joined, and the pool encodes such a frame whole rather than failing it.
TEST(JpegEncoderPool, AFrameWhoseStripsCannotBeJoinedIsEncodedWhole) {
  JpegEncoderPool pool(2);
  const ImageRgba picture = test_picture(160, 2 * JpegEncoderPool::kLeastStripRows);
  ASSERT_EQ(setenv("TJ_RESTART", "1", 1), 0);
  EXPECT_TRUE(has_restart_markers(encode_jpeg_rows(picture, 0, 64, {80})));  // read, so tested
  std::vector<std::uint8_t> jpeg;
  EXPECT_NO_THROW(jpeg = pool.encode(picture, {80}).get());
  unsetenv("TJ_RESTART");
  EXPECT_EQ(decode_jpeg(jpeg).pixels, decode_jpeg(encode_jpeg(picture, {80})).pixels);
}

TEST(JpegEncoderPool, EncodesConcurrentlyWhatOneThreadEncodes) {
  JpegEncoderPool pool(2);
  std::vector<ImageRgba> pictures;
  for (int k = 0; k < 8; ++k) pictures.push_back(test_picture(160 + k, 90 + k));
  std::vector<std::future<std::vector<std::uint8_t>>> jpegs;
  for (const auto& picture : pictures) jpegs.push_back(pool.encode(picture, {85}));
  for (std::size_t k = 0; k < pictures.size(); ++k) {
    EXPECT_EQ(jpegs[k].get(), encode_jpeg(pictures[k], {85}));
  }
  auto bad = pool.encode(pictures[0], {0});
  EXPECT_THROW(bad.get(), std::invalid_argument);
}

}  // namespace
}  // namespace fluidcast::codec

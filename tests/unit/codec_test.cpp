// JPEG and PNG: round trips, quality, sizes, bad input, and the encoder pool.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "fluidcast/codec/jpeg.h"
#include "fluidcast/codec/jpeg_encoder_pool.h"
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
  EXPECT_THROW(ImageRgba(0, 5), std::invalid_argument);
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

#include "fluidcast/codec/jpeg_encoder_pool.h"

#include <boost/asio/post.hpp>
#include <memory>
#include <thread>

namespace fluidcast::codec {
namespace {

unsigned resolve(unsigned threads) {
  return threads > 0 ? threads : std::max(1u, std::thread::hardware_concurrency());
}

}  // namespace

JpegEncoderPool::JpegEncoderPool(unsigned threads) : threads_(resolve(threads)), pool_(threads_) {}

JpegEncoderPool::~JpegEncoderPool() { pool_.join(); }

std::future<std::vector<std::uint8_t>> JpegEncoderPool::encode(ImageRgba image,
                                                               JpegOptions options) {
  auto task = std::make_shared<std::packaged_task<std::vector<std::uint8_t>()>>(
      [image = std::move(image), options] { return encode_jpeg(image, options); });
  auto result = task->get_future();
  boost::asio::post(pool_, [task] { (*task)(); });
  return result;
}

}  // namespace fluidcast::codec

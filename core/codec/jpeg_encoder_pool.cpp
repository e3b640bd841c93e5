#include "fluidcast/codec/jpeg_encoder_pool.h"

#include <boost/asio/post.hpp>
#include <chrono>
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

std::future<std::vector<std::uint8_t>> JpegEncoderPool::encode(Image image, JpegOptions options) {
  auto promise = std::make_shared<std::promise<std::vector<std::uint8_t>>>();
  auto result = promise->get_future();
  encode(std::move(image), options,
         [promise](std::vector<std::uint8_t> jpeg, double, std::exception_ptr error) {
           if (error) {
             promise->set_exception(error);
           } else {
             promise->set_value(std::move(jpeg));
           }
         });
  return result;
}

void JpegEncoderPool::encode(Image image, JpegOptions options, EncodeDone done) {
  boost::asio::post(pool_, [image = std::move(image), options, done = std::move(done)] {
    const auto start = std::chrono::steady_clock::now();
    std::vector<std::uint8_t> jpeg;
    std::exception_ptr error;
    try {
      jpeg = encode_jpeg(image, options);
    } catch (...) {
      error = std::current_exception();
    }
    const std::chrono::duration<double, std::milli> took = std::chrono::steady_clock::now() - start;
    done(std::move(jpeg), took.count(), error);
  });
}

}  // namespace fluidcast::codec

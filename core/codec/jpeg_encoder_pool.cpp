#include "fluidcast/codec/jpeg_encoder_pool.h"

#include <algorithm>
#include <boost/asio/post.hpp>
#include <chrono>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>

#include "fluidcast/codec/jpeg_strips.h"

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
  const int height = height_of(image);
  const int strips = std::clamp(height / kLeastStripRows, 1, static_cast<int>(threads_));
  const int strip_rows = jpeg_strip_rows(height, strips);
  // One frame's strips on as many threads; the last to finish joins them and reports.
  struct Frame {
    Image image;
    JpegOptions options;
    EncodeDone done;
    std::optional<std::chrono::steady_clock::time_point> started;  // its first strip
    int strip_rows;
    std::vector<std::vector<std::uint8_t>> strips;
    std::exception_ptr error;
    std::mutex mutex;
    int left;
  };
  const int count = std::max(1, (height + strip_rows - 1) / strip_rows);  // an empty image: one
  auto frame = std::make_shared<Frame>();
  frame->image = std::move(image);
  frame->options = options;
  frame->done = std::move(done);
  frame->strip_rows = strip_rows;
  frame->strips.resize(static_cast<std::size_t>(count));
  frame->left = count;
  for (int k = 0; k < count; ++k) {
    boost::asio::post(pool_, [frame, k, height] {
      {
        const std::lock_guard lock(frame->mutex);
        if (!frame->started) frame->started = std::chrono::steady_clock::now();
      }
      const int first = k * frame->strip_rows;
      std::vector<std::uint8_t> strip;
      std::exception_ptr error;
      try {
        strip = encode_jpeg_rows(frame->image, first, std::min(frame->strip_rows, height - first),
                                 frame->options);
      } catch (...) {
        error = std::current_exception();
      }
      {
        const std::lock_guard lock(frame->mutex);
        frame->strips[static_cast<std::size_t>(k)] = std::move(strip);
        if (error && !frame->error) frame->error = error;
        if (--frame->left > 0) return;
      }
      std::vector<std::uint8_t> jpeg;
      if (!frame->error) {
        try {
          try {
            jpeg = join_jpeg_strips(frame->strips, frame->strip_rows);
          } catch (const std::invalid_argument&) {
            // Strips that cannot be joined (more blocks than a restart interval counts,
            // TurboJPEG's environment asking for another kind of JPEG): the frame whole.
            jpeg = encode_jpeg(frame->image, frame->options);
          }
        } catch (...) {
          frame->error = std::current_exception();
        }
      }
      const std::chrono::duration<double, std::milli> took =
          std::chrono::steady_clock::now() - *frame->started;
      frame->done(std::move(jpeg), took.count(), frame->error);
    });
  }
}

}  // namespace fluidcast::codec

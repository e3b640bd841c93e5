// JPEG encoding on a pool of threads (one per core by default), so that frames from the GPU are
// encoded while the next ones render, and throughput grows with cores. A frame of at least
// 2 · kLeastStripRows rows is cut into strips encoded on several threads at once and joined
// (jpeg_strips.h): the same pixels, its encode's latency shortened. Each worker reuses its own
// TurboJPEG handle.
#pragma once

#include <boost/asio/thread_pool.hpp>
#include <cstdint>
#include <exception>
#include <functional>
#include <future>
#include <vector>

#include "fluidcast/codec/jpeg.h"

namespace fluidcast::codec {

class JpegEncoderPool {
 public:
  // 0 threads: one per core.
  explicit JpegEncoderPool(unsigned threads = 0);
  // Finishes what was queued, then stops.
  ~JpegEncoderPool();
  JpegEncoderPool(const JpegEncoderPool&) = delete;
  JpegEncoderPool& operator=(const JpegEncoderPool&) = delete;

  unsigned threads() const { return threads_; }
  // Rows per thread a frame needs to be cut: thinner strips cost more in set-up than they save.
  static constexpr int kLeastStripRows = 64;

  // The future holds the JPEG, or the exception encoding threw (bad options, say).
  std::future<std::vector<std::uint8_t>> encode(Image image, JpegOptions options);
  // The same, for a caller that must not wait: `done` runs on a pool thread with the JPEG and
  // the milliseconds encoding took (from its first strip's start to the JPEG), or with the
  // exception encoding threw (then the JPEG is empty).
  using EncodeDone =
      std::function<void(std::vector<std::uint8_t> jpeg, double milliseconds, std::exception_ptr)>;
  void encode(Image image, JpegOptions options, EncodeDone done);

 private:
  unsigned threads_;
  boost::asio::thread_pool pool_;
};

}  // namespace fluidcast::codec

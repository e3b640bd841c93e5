#include "fluidcast/sim/fork_join_pool.h"

#include <algorithm>

namespace fluidcast::sim {
namespace {
constexpr std::size_t kMinItemsPerChunk = 256;
}

ForkJoinPool::ForkJoinPool(unsigned threads) {
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  workers_.reserve(threads - 1);
  for (unsigned chunk = 1; chunk < threads; ++chunk) {
    workers_.emplace_back([this, chunk](std::stop_token stop) { worker_loop(chunk, stop); });
  }
}

ForkJoinPool::~ForkJoinPool() {
  for (auto& w : workers_) w.request_stop();
  generation_.fetch_add(1, std::memory_order_release);
  generation_.notify_all();
  // std::jthread joins on destruction.
}

unsigned ForkJoinPool::chunks_for(std::size_t n) const {
  const std::size_t useful = std::max<std::size_t>(1, n / kMinItemsPerChunk);
  return static_cast<unsigned>(std::min<std::size_t>(size(), useful));
}

void ForkJoinPool::run(std::size_t n, void* body, Trampoline trampoline) {
  const unsigned chunks = chunks_for(n);
  if (chunks == 1) {
    trampoline(body, 0, 0, n);
    return;
  }
  body_ = body;
  trampoline_ = trampoline;
  n_ = n;
  chunks_ = chunks;
  pending_.store(static_cast<unsigned>(workers_.size()), std::memory_order_relaxed);
  generation_.fetch_add(1, std::memory_order_release);
  generation_.notify_all();

  trampoline(body, 0, 0, chunk_begin(n, chunks, 1));

  for (unsigned left = pending_.load(std::memory_order_acquire); left != 0;
       left = pending_.load(std::memory_order_acquire)) {
    pending_.wait(left, std::memory_order_acquire);
  }
}

void ForkJoinPool::worker_loop(unsigned chunk, std::stop_token stop) {
  unsigned seen = 0;
  while (true) {
    generation_.wait(seen, std::memory_order_acquire);
    seen = generation_.load(std::memory_order_acquire);
    if (stop.stop_requested()) return;
    if (chunk < chunks_) {
      trampoline_(body_, chunk, chunk_begin(n_, chunks_, chunk), chunk_begin(n_, chunks_, chunk + 1));
    }
    if (pending_.fetch_sub(1, std::memory_order_acq_rel) == 1) pending_.notify_one();
  }
}

}  // namespace fluidcast::sim

#include "fluidcast/sim/fork_join_pool.h"

#include <algorithm>
#include <utility>

namespace fluidcast::sim {
namespace {
constexpr std::size_t kMinItemsPerChunk = 256;
}

ForkJoinPool::ForkJoinPool(unsigned threads) {
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency());
  workers_.reserve(threads - 1);
  try {
    for (unsigned chunk = 1; chunk < threads; ++chunk) {
      workers_.emplace_back([this, chunk](std::stop_token stop) { worker_loop(chunk, stop); });
    }
  } catch (...) {
    stop_workers();
    throw;
  }
}

ForkJoinPool::~ForkJoinPool() { stop_workers(); }

// Joined here, not by the members' destructors: the workers use the atomics declared after them.
void ForkJoinPool::stop_workers() noexcept {
  for (auto& w : workers_) w.request_stop();
  generation_.fetch_add(1, std::memory_order_release);
  generation_.notify_all();
  for (auto& w : workers_) w.join();
  workers_.clear();
}

unsigned ForkJoinPool::chunks_for(std::size_t n) const {
  const std::size_t useful = std::max<std::size_t>(1, n / kMinItemsPerChunk);
  return static_cast<unsigned>(std::min<std::size_t>(size(), useful));
}

void ForkJoinPool::run_chunk(unsigned chunk) noexcept {
  try {
    trampoline_(body_, chunk, chunk_begin(n_, chunks_, chunk), chunk_begin(n_, chunks_, chunk + 1));
  } catch (...) {
    const std::lock_guard lock(error_mutex_);
    if (!error_) error_ = std::current_exception();
  }
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
  error_ = nullptr;
  pending_.store(static_cast<unsigned>(workers_.size()), std::memory_order_relaxed);
  generation_.fetch_add(1, std::memory_order_release);
  generation_.notify_all();

  run_chunk(0);

  for (unsigned left = pending_.load(std::memory_order_acquire); left != 0;
       left = pending_.load(std::memory_order_acquire)) {
    pending_.wait(left, std::memory_order_acquire);
  }
  if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
}

void ForkJoinPool::worker_loop(unsigned chunk, std::stop_token stop) {
  unsigned seen = 0;
  while (true) {
    generation_.wait(seen, std::memory_order_acquire);
    seen = generation_.load(std::memory_order_acquire);
    if (stop.stop_requested()) return;
    if (chunk < chunks_) run_chunk(chunk);
    if (pending_.fetch_sub(1, std::memory_order_acq_rel) == 1) pending_.notify_one();
  }
}

}  // namespace fluidcast::sim

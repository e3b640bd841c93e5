#include "fluidcast/sim/fork_join_pool.h"

#include <algorithm>
#include <chrono>
#include <thread>
#include <utility>

namespace fluidcast::sim {
namespace {
constexpr std::size_t kMinItemsPerChunk = 256;

// A solver step is a train of passes of 0.1–10 ms each, with short serial stretches between
// them. Parking a thread in the kernel and waking it costs about as much as a small pass
// (measured on a 2-vCPU VM: two threads were no faster than one at 5000 particles; spinning up to
// ~0.5 ms made them 1.8× faster, ~0.1 ms only 1.35×), so waits spin for a while before they block
// — by time, since a pause instruction lasts 10 to 140 cycles depending on the CPU. A pool with
// more threads than cores never spins: a spinning thread would take the core from one with work.
// For the same reason a spinning thread yields every few microseconds: when another process keeps
// the cores busy (two solvers side by side), the thread it waits for may be the one it would keep
// out (measured: two CPU-solver tests run together took 8.3 s without the yield, 4.8 s with it,
// where one after the other they take 5.6 s).
constexpr auto kSpinBeforeBlocking = std::chrono::microseconds(500);

inline void cpu_relax() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

// Waits until `value` differs from `old`: spins first (when allowed), then blocks.
template <class T>
T wait_while_equal(const std::atomic<T>& value, T old, bool spin) {
  if (spin) {
    const auto give_up = std::chrono::steady_clock::now() + kSpinBeforeBlocking;
    do {
      for (int k = 0; k < 64; ++k) {
        const T now = value.load(std::memory_order_acquire);
        if (now != old) return now;
        cpu_relax();
      }
      std::this_thread::yield();
    } while (std::chrono::steady_clock::now() < give_up);
  }
  value.wait(old, std::memory_order_acquire);
  return value.load(std::memory_order_acquire);
}
}  // namespace

ForkJoinPool::ForkJoinPool(unsigned threads) {
  const unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  if (threads == 0) threads = cores;
  spin_ = threads <= cores;
  workers_.reserve(threads - 1);
  try {
    for (unsigned chunk = 1; chunk < threads; ++chunk) {
      workers_.emplace_back([this, chunk] { worker_loop(chunk); });
    }
  } catch (...) {
    stop_workers();
    throw;
  }
}

ForkJoinPool::~ForkJoinPool() { stop_workers(); }

// Joined here, not by the members' destructors: the workers use the atomics declared after them.
void ForkJoinPool::stop_workers() noexcept {
  stopping_.store(true, std::memory_order_release);
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

  for (unsigned left = pending_.load(std::memory_order_acquire); left != 0;) {
    left = wait_while_equal(pending_, left, spin_);
  }
  if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
}

void ForkJoinPool::worker_loop(unsigned chunk) {
  unsigned seen = 0;
  while (true) {
    seen = wait_while_equal(generation_, seen, spin_);
    if (stopping_.load(std::memory_order_acquire)) return;
    if (chunk < chunks_) run_chunk(chunk);
    if (pending_.fetch_sub(1, std::memory_order_acq_rel) == 1) pending_.notify_one();
  }
}

}  // namespace fluidcast::sim

// A fixed set of threads that splits [0, n) into contiguous chunks, one per thread, and returns
// when all are done. The split depends only on n and the thread count, so results are deterministic
// for a fixed thread count. The calling thread runs chunk 0.
#pragma once

#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace fluidcast::sim {

class ForkJoinPool {
 public:
  // threads == 0: one per core.
  explicit ForkJoinPool(unsigned threads);
  ~ForkJoinPool();
  ForkJoinPool(const ForkJoinPool&) = delete;
  ForkJoinPool& operator=(const ForkJoinPool&) = delete;

  unsigned size() const { return static_cast<unsigned>(workers_.size()) + 1; }

  // Calls body(chunk, begin, end) for each chunk of [0, n); chunk < size(). Small ranges use fewer
  // chunks, since waking a thread costs more than a few hundred particles of work. If a chunk
  // throws, the others still finish and the first exception is rethrown here.
  template <class Body>
  void for_chunks(std::size_t n, Body&& body) {
    run(n, &body, [](void* b, unsigned chunk, std::size_t begin, std::size_t end) {
      (*static_cast<Body*>(b))(chunk, begin, end);
    });
  }

  // Calls body(i) for every i in [0, n).
  template <class Body>
  void for_each(std::size_t n, Body&& body) {
    for_chunks(n, [&](unsigned, std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) body(i);
    });
  }

  // The [begin, end) of chunk `chunk` when [0, n) is split into `chunks` parts.
  static std::size_t chunk_begin(std::size_t n, unsigned chunks, unsigned chunk) {
    return n * chunk / chunks;
  }
  unsigned chunks_for(std::size_t n) const;

 private:
  using Trampoline = void (*)(void*, unsigned, std::size_t, std::size_t);
  void run(std::size_t n, void* body, Trampoline trampoline);
  void run_chunk(unsigned chunk) noexcept;
  void worker_loop(unsigned chunk);
  void stop_workers() noexcept;

  // std::thread and a flag rather than std::jthread: the WebAssembly build's libc++ has no jthread.
  std::vector<std::thread> workers_;
  std::atomic<bool> stopping_{false};
  // The current job, published by bumping generation_.
  void* body_ = nullptr;
  Trampoline trampoline_ = nullptr;
  std::size_t n_ = 0;
  unsigned chunks_ = 0;
  std::atomic<unsigned> generation_{0};
  std::atomic<unsigned> pending_{0};
  bool spin_ = true;  // waits spin before blocking; off when threads outnumber cores
  std::mutex error_mutex_;
  std::exception_ptr error_;
};

}  // namespace fluidcast::sim

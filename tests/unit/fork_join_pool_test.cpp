#include "fluidcast/sim/fork_join_pool.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <thread>
#include <stdexcept>
#include <vector>

namespace fluidcast::sim {
namespace {

TEST(ForkJoinPool, VisitsEveryIndexExactlyOnce) {
  for (unsigned threads : {1u, 2u, 5u}) {
    ForkJoinPool pool(threads);
    for (std::size_t n : {0u, 1u, 255u, 256u, 10'000u, 100'003u}) {
      std::vector<int> hits(n, 0);
      pool.for_each(n, [&](std::size_t i) { ++hits[i]; });
      for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(hits[i], 1) << "n " << n << " i " << i;
    }
  }
}

TEST(ForkJoinPool, ChunksAreContiguousAndCoverTheRange) {
  ForkJoinPool pool(3);
  const std::size_t n = 9000;
  std::vector<std::pair<std::size_t, std::size_t>> ranges(pool.size(), {0, 0});
  pool.for_chunks(n, [&](unsigned chunk, std::size_t begin, std::size_t end) {
    ranges[chunk] = {begin, end};
  });
  std::size_t expected_begin = 0;
  for (const auto& [begin, end] : ranges) {
    EXPECT_EQ(begin, expected_begin);
    expected_begin = end;
  }
  EXPECT_EQ(expected_begin, n);
}

TEST(ForkJoinPool, ManyShortJobsInARow) {
  ForkJoinPool pool(4);
  std::atomic<std::size_t> total{0};
  for (int job = 0; job < 2000; ++job) {
    pool.for_chunks(4096, [&](unsigned, std::size_t begin, std::size_t end) {
      total.fetch_add(end - begin, std::memory_order_relaxed);
    });
  }
  EXPECT_EQ(total.load(), 2000u * 4096u);
}

TEST(ForkJoinPool, AnExceptionInAnyChunkReachesTheCallerAfterAllChunksFinish) {
  ForkJoinPool pool(3);
  for (unsigned thrower = 0; thrower < 3; ++thrower) {
    std::atomic<int> finished{0};
    EXPECT_THROW(pool.for_chunks(30000,
                                 [&](unsigned chunk, std::size_t, std::size_t) {
                                   if (chunk == thrower) throw std::runtime_error("chunk failed");
                                   finished.fetch_add(1);
                                 }),
                 std::runtime_error);
    EXPECT_EQ(finished.load(), 2);
  }
  std::atomic<std::size_t> total{0};
  pool.for_each(30000, [&](std::size_t) { total.fetch_add(1, std::memory_order_relaxed); });
  EXPECT_EQ(total.load(), 30000u);
}

TEST(ForkJoinPool, ZeroMeansOnePerCore) {
  EXPECT_EQ(ForkJoinPool(0).size(), std::max(1u, std::thread::hardware_concurrency()));
  EXPECT_EQ(ForkJoinPool(3).size(), 3u);
}

}  // namespace
}  // namespace fluidcast::sim

#include <gtest/gtest.h>

#include <cstdint>

#include "fluidcast/gpu/command_slot.h"

namespace fluidcast::gpu {
namespace {

TEST(TimestampTicksBetween, A64BitCounterIsPlainSubtraction) {
  EXPECT_EQ(timestamp_ticks_between(1000, 1250, 64), 250u);
}

TEST(TimestampTicksBetween, ANarrowerCounterThatWrappedCountsOnPastItsTop) {
  // A 36-bit counter (some GPUs' timestampValidBits) wrapping between the two marks.
  const std::uint64_t top = (std::uint64_t{1} << 36) - 1;
  EXPECT_EQ(timestamp_ticks_between(top - 9, 20, 36), 30u);
  EXPECT_EQ(timestamp_ticks_between(5, 25, 36), 20u);
}

TEST(TimestampTicksBetween, ATimestampBeforeTheFirstMeasuresNothing) {
  EXPECT_EQ(timestamp_ticks_between(1250, 1000, 64), 0u);
  EXPECT_EQ(timestamp_ticks_between(1250, 1000, 36), 0u);
  EXPECT_EQ(timestamp_ticks_between(1000, 1250, 0), 0u);  // no timestamps at all
}

}  // namespace
}  // namespace fluidcast::gpu

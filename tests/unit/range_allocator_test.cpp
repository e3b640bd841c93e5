#include "fluidcast/gpu/range_allocator.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "fluidcast/gpu/memory.h"

namespace fluidcast::gpu {
namespace {

TEST(RangeAllocator, AlignsAndFillsFirstFit) {
  RangeAllocator ranges(1024);
  EXPECT_EQ(ranges.allocate(10, 1), 0u);
  EXPECT_EQ(ranges.allocate(16, 64), 64u);  // the gap [10, 64) stays free
  EXPECT_EQ(ranges.allocate(20, 2), 10u);   // and is used first
  EXPECT_EQ(ranges.free_bytes(), 1024u - 46u);
  EXPECT_FALSE(ranges.allocate(2000, 1).has_value());
}

TEST(RangeAllocator, FreedNeighboursMergeBackIntoOneRange) {
  RangeAllocator ranges(300);
  const auto a = *ranges.allocate(100, 1), b = *ranges.allocate(100, 1),
             c = *ranges.allocate(100, 1);
  EXPECT_FALSE(ranges.allocate(1, 1).has_value());
  ranges.free(a);
  ranges.free(c);
  EXPECT_FALSE(ranges.allocate(200, 1).has_value());  // two holes of 100, not one of 200
  ranges.free(b);
  EXPECT_EQ(ranges.allocate(300, 1), 0u);
}

TEST(RangeAllocator, BadRequestsAndDoubleFreesAreErrors) {
  RangeAllocator ranges(64);
  EXPECT_THROW(ranges.allocate(0, 1), std::invalid_argument);
  EXPECT_THROW(ranges.allocate(8, 3), std::invalid_argument);
  const auto a = *ranges.allocate(8, 8);
  ranges.free(a);
  EXPECT_THROW(ranges.free(a), std::logic_error);
  EXPECT_THROW(ranges.free(5), std::logic_error);
}

TEST(RangeAllocator, RandomUseNeverOverlapsAndEndsEmpty) {
  RangeAllocator ranges(1 << 16);
  std::mt19937 random(1);
  std::vector<std::pair<std::uint64_t, std::uint64_t>> live;
  for (int k = 0; k < 5000; ++k) {
    if (!live.empty() && random() % 2 == 0) {
      const std::size_t pick = random() % live.size();
      ranges.free(live[pick].first);
      live.erase(live.begin() + static_cast<std::ptrdiff_t>(pick));
      continue;
    }
    const std::uint64_t size = 1 + random() % 700, alignment = 1u << (random() % 8);
    const auto offset = ranges.allocate(size, alignment);
    if (!offset) continue;
    EXPECT_EQ(*offset % alignment, 0u);
    for (const auto& [other, other_size] : live) {
      ASSERT_TRUE(*offset + size <= other || other + other_size <= *offset) << "overlap";
    }
    live.emplace_back(*offset, size);
  }
  for (const auto& range : live) ranges.free(range.first);
  EXPECT_TRUE(ranges.empty());
  EXPECT_EQ(ranges.free_bytes(), 1u << 16);
  EXPECT_EQ(ranges.allocate(1 << 16, 1), 0u);
}

// Buffers and images of any sizes and alignments in one block, images allocated as the allocator
// asks for them: no page of bufferImageGranularity holds both a buffer's bytes and an image's.
TEST(RangeAllocator, ImagesAndBuffersNeverShareAGranularityPage) {
  constexpr VkDeviceSize kGranularity = 1024;
  RangeAllocator ranges(4 << 20);
  std::mt19937 random(2);
  struct Range {
    VkDeviceSize first, last;  // bytes [first, last]
    bool image;
  };
  std::vector<Range> live;
  const auto page = [](VkDeviceSize byte) { return byte / kGranularity; };
  for (int k = 0; k < 400; ++k) {
    const bool image = random() % 2 == 0;
    VkMemoryRequirements asked{};
    asked.size = 1 + random() % 3000;
    asked.alignment = VkDeviceSize{1} << (random() % 9);
    const VkMemoryRequirements given =
        requirements_for(asked, image ? Resource::optimal_image : Resource::buffer, kGranularity);
    EXPECT_GE(given.size, asked.size);
    EXPECT_EQ(given.alignment % asked.alignment, 0u);
    const auto offset = ranges.allocate(given.size, given.alignment);
    ASSERT_TRUE(offset.has_value());
    const Range placed{*offset, *offset + asked.size - 1, image};
    for (const Range& other : live) {
      if (other.image == placed.image) continue;
      ASSERT_TRUE(page(placed.last) < page(other.first) || page(other.last) < page(placed.first))
          << (image ? "an image" : "a buffer") << " at " << placed.first << " shares a page with "
          << (image ? "a buffer" : "an image") << " at " << other.first;
    }
    live.push_back(placed);
  }
}

}  // namespace
}  // namespace fluidcast::gpu

// First-fit allocation of aligned ranges inside one block of memory, with free neighbours merged
// back together. Pure bookkeeping (no Vulkan), so that it can be tested on its own.
#pragma once

#include <cstdint>
#include <map>
#include <optional>

namespace fluidcast::gpu {

class RangeAllocator {
 public:
  explicit RangeAllocator(std::uint64_t size);

  // The offset of a new range of `size` bytes aligned to `alignment` (a power of two), or nothing
  // when no free range is large enough. Throws std::invalid_argument for size 0 or a bad alignment.
  std::optional<std::uint64_t> allocate(std::uint64_t size, std::uint64_t alignment);
  // Returns the range that allocate() gave at `offset`. Throws std::logic_error for an offset it
  // did not give or already took back.
  void free(std::uint64_t offset);

  std::uint64_t size() const { return size_; }
  std::uint64_t free_bytes() const { return free_bytes_; }
  bool empty() const { return used_.empty(); }

 private:
  std::uint64_t size_;
  std::uint64_t free_bytes_;
  std::map<std::uint64_t, std::uint64_t> free_;  // offset → size, never two adjacent
  std::map<std::uint64_t, std::uint64_t> used_;  // offset → size
};

}  // namespace fluidcast::gpu

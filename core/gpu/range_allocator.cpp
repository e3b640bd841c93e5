#include "fluidcast/gpu/range_allocator.h"

#include <stdexcept>
#include <string>

namespace fluidcast::gpu {

RangeAllocator::RangeAllocator(std::uint64_t size) : size_(size), free_bytes_(size) {
  if (size > 0) free_.emplace(0, size);
}

std::optional<std::uint64_t> RangeAllocator::allocate(std::uint64_t size, std::uint64_t alignment) {
  if (size == 0) throw std::invalid_argument("range allocator: size must be positive");
  if (alignment == 0 || (alignment & (alignment - 1)) != 0) {
    throw std::invalid_argument("range allocator: alignment must be a power of two, got " +
                                std::to_string(alignment));
  }
  for (auto it = free_.begin(); it != free_.end(); ++it) {
    const auto [start, length] = *it;
    const std::uint64_t aligned = (start + alignment - 1) & ~(alignment - 1);
    if (aligned - start >= length || length - (aligned - start) < size) continue;
    const std::uint64_t end = start + length;
    free_.erase(it);
    if (aligned > start) free_.emplace(start, aligned - start);
    if (aligned + size < end) free_.emplace(aligned + size, end - (aligned + size));
    used_.emplace(aligned, size);
    free_bytes_ -= size;
    return aligned;
  }
  return std::nullopt;
}

void RangeAllocator::free(std::uint64_t offset) {
  const auto used = used_.find(offset);
  if (used == used_.end()) {
    throw std::logic_error("range allocator: no range was allocated at offset " +
                           std::to_string(offset));
  }
  std::uint64_t start = offset, length = used->second;
  used_.erase(used);
  free_bytes_ += length;
  auto next = free_.lower_bound(start);
  if (next != free_.end() && next->first == start + length) {
    length += next->second;
    next = free_.erase(next);
  }
  if (next != free_.begin()) {
    const auto previous = std::prev(next);
    if (previous->first + previous->second == start) {
      start = previous->first;
      length += previous->second;
      free_.erase(previous);
    }
  }
  free_.emplace(start, length);
}

}  // namespace fluidcast::gpu

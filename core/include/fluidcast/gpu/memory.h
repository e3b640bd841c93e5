// Device memory, sub-allocated from large blocks (one vkAllocateMemory per block, not per buffer),
// chosen by what the memory is for rather than by raw property flags.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

#include "fluidcast/gpu/handle.h"
#include "fluidcast/gpu/range_allocator.h"

namespace fluidcast::gpu {

enum class MemoryDomain {
  device,    // GPU only: particles, grids, scratch
  upload,    // host writes, GPU reads: staging for uploads; mapped
  readback,  // GPU writes, host reads: snapshots, statistics, frames; mapped and cached if possible
};

// What a range holds. Linear resources (buffers) and optimal-tiling images must not share a
// page of bufferImageGranularity (1 KiB on NVIDIA's GPUs; lavapipe's is smaller), or they may
// alias.
enum class Resource { buffer, optimal_image };

// `requirements` as allocated for `resource`: an image's range whole pages of `granularity`, so
// no buffer lands on a page of it.
VkMemoryRequirements requirements_for(const VkMemoryRequirements& requirements, Resource resource,
                                      VkDeviceSize granularity);

class MemoryAllocator;

// One sub-allocated range; returns itself to its block when destroyed.
class Allocation {
 public:
  Allocation() = default;
  ~Allocation() { release(); }
  Allocation(Allocation&& other) noexcept { *this = std::move(other); }
  Allocation& operator=(Allocation&& other) noexcept;
  Allocation(const Allocation&) = delete;
  Allocation& operator=(const Allocation&) = delete;

  VkDeviceMemory memory() const { return memory_; }
  VkDeviceSize offset() const { return offset_; }
  VkDeviceSize size() const { return size_; }
  // The host address of the range in the mapped domains, nullptr in the device domain.
  void* mapped() const { return mapped_; }

 private:
  friend class MemoryAllocator;
  void release();

  MemoryAllocator* owner_ = nullptr;
  std::size_t block_ = 0;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  VkDeviceSize offset_ = 0;
  VkDeviceSize size_ = 0;
  void* mapped_ = nullptr;
};

class MemoryAllocator {
 public:
  static constexpr VkDeviceSize kBlockSize = VkDeviceSize{64} << 20;

  // `largest_allocation`: the most the device allocates in one piece (DeviceInfo); `limit`: the
  // most bytes its blocks may hold in all (0: no limit but the device's).
  MemoryAllocator(VkDevice device, VkPhysicalDevice physical_device,
                  VkDeviceSize largest_allocation, VkDeviceSize limit = 0);
  ~MemoryAllocator();
  MemoryAllocator(const MemoryAllocator&) = delete;
  MemoryAllocator& operator=(const MemoryAllocator&) = delete;

  // Requests larger than a block get a block of their own, freed with it; of standard blocks that
  // empty, one per memory type is kept for the next request. Every block allows buffer device
  // addresses. Throws VulkanError (VK_ERROR_OUT_OF_DEVICE_MEMORY and the like) when memory runs
  // out, when a new block would take its blocks past the limit, or for a request larger than the
  // device allocates in one piece (maxMemoryAllocationSize).
  Allocation allocate(const VkMemoryRequirements& requirements, MemoryDomain domain,
                      Resource resource = Resource::buffer);

  // How many blocks of memory are allocated now, their bytes, and how many vkAllocateMemory calls
  // so far.
  std::size_t block_count() const;
  std::uint64_t block_bytes() const;
  std::uint64_t allocations_made() const;

 private:
  friend class Allocation;
  struct Block {
    UniqueMemory memory;
    std::uint32_t type = 0;
    void* mapped = nullptr;
    std::unique_ptr<RangeAllocator> ranges;  // null once the block is freed
  };
  std::uint32_t pick_type(std::uint32_t allowed_types, MemoryDomain domain) const;
  void free(std::size_t block, VkDeviceSize offset);

  VkDevice device_;
  VkPhysicalDeviceMemoryProperties properties_{};
  VkDeviceSize granularity_ = 1;  // bufferImageGranularity
  VkDeviceSize limit_ = 0;
  VkDeviceSize largest_allocation_ = 0;
  VkDeviceSize block_bytes_ = 0;  // held in blocks now
  mutable std::mutex mutex_;
  std::vector<Block> blocks_;
  std::uint64_t allocations_made_ = 0;
};

}  // namespace fluidcast::gpu

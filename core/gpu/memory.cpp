#include "fluidcast/gpu/memory.h"

#include <algorithm>
#include <string>
#include <utility>

#include "fluidcast/gpu/vk_check.h"

namespace fluidcast::gpu {

Allocation& Allocation::operator=(Allocation&& other) noexcept {
  if (this != &other) {
    release();
    owner_ = std::exchange(other.owner_, nullptr);
    block_ = other.block_;
    memory_ = std::exchange(other.memory_, VK_NULL_HANDLE);
    offset_ = other.offset_;
    size_ = other.size_;
    mapped_ = std::exchange(other.mapped_, nullptr);
  }
  return *this;
}

void Allocation::release() {
  if (owner_) std::exchange(owner_, nullptr)->free(block_, offset_);
  memory_ = VK_NULL_HANDLE;
  mapped_ = nullptr;
}

VkMemoryRequirements requirements_for(const VkMemoryRequirements& requirements, Resource resource,
                                      VkDeviceSize granularity) {
  if (resource == Resource::buffer || granularity <= 1) return requirements;
  VkMemoryRequirements whole_pages = requirements;
  whole_pages.alignment = std::max(requirements.alignment, granularity);
  whole_pages.size = (requirements.size + granularity - 1) / granularity * granularity;
  return whole_pages;
}

MemoryAllocator::MemoryAllocator(VkDevice device, VkPhysicalDevice physical_device,
                                 VkDeviceSize largest_allocation, VkDeviceSize limit)
    : device_(device), limit_(limit), largest_allocation_(largest_allocation) {
  vkGetPhysicalDeviceMemoryProperties(physical_device, &properties_);
  VkPhysicalDeviceProperties device_properties;
  vkGetPhysicalDeviceProperties(physical_device, &device_properties);
  granularity_ = std::max<VkDeviceSize>(device_properties.limits.bufferImageGranularity, 1);
}

MemoryAllocator::~MemoryAllocator() = default;

std::uint32_t MemoryAllocator::pick_type(std::uint32_t allowed_types, MemoryDomain domain) const {
  using Flags = VkMemoryPropertyFlags;
  constexpr Flags visible =
      VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  // Preferred first, then what must hold at least.
  std::vector<Flags> wanted;
  switch (domain) {
    case MemoryDomain::device:
      wanted = {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0};
      break;
    case MemoryDomain::upload:
      wanted = {visible};
      break;
    case MemoryDomain::readback:
      wanted = {visible | VK_MEMORY_PROPERTY_HOST_CACHED_BIT, visible};
      break;
  }
  for (const Flags flags : wanted) {
    for (std::uint32_t t = 0; t < properties_.memoryTypeCount; ++t) {
      if ((allowed_types & (1u << t)) &&
          (properties_.memoryTypes[t].propertyFlags & flags) == flags) {
        return t;
      }
    }
  }
  throw VulkanError(
      "no memory type suits the request (allowed types mask " + std::to_string(allowed_types) + ")",
      VK_ERROR_FEATURE_NOT_PRESENT);
}

Allocation MemoryAllocator::allocate(const VkMemoryRequirements& asked, MemoryDomain domain,
                                     Resource resource) {
  const VkMemoryRequirements requirements = requirements_for(asked, resource, granularity_);
  const std::uint32_t type = pick_type(requirements.memoryTypeBits, domain);
  const VkDeviceSize alignment = std::max<VkDeviceSize>(requirements.alignment, 1);
  std::lock_guard lock(mutex_);
  const auto fill = [&](std::size_t index, VkDeviceSize offset) {
    Allocation a;
    a.owner_ = this;
    a.block_ = index;
    a.memory_ = blocks_[index].memory.get();
    a.offset_ = offset;
    a.size_ = requirements.size;
    a.mapped_ =
        blocks_[index].mapped ? static_cast<std::byte*>(blocks_[index].mapped) + offset : nullptr;
    return a;
  };
  for (std::size_t i = 0; i < blocks_.size(); ++i) {
    Block& block = blocks_[i];
    if (!block.ranges || block.type != type) continue;
    if (const auto offset = block.ranges->allocate(requirements.size, alignment))
      return fill(i, *offset);
  }

  const VkDeviceSize size = std::max(kBlockSize, requirements.size);
  const auto mib = [](VkDeviceSize bytes) { return std::to_string(bytes >> 20) + " MiB"; };
  // Past it the driver may fail the allocation or take it and misbehave (the limit is a promise
  // the application keeps): refused here as the out-of-memory it amounts to.
  if (size > largest_allocation_) {
    throw VulkanError("GPU memory: " + mib(size) + " in one piece is more than this device " +
                          "allocates at once (" + mib(largest_allocation_) + ")",
                      VK_ERROR_OUT_OF_DEVICE_MEMORY);
  }
  if (limit_ > 0 && block_bytes_ + size > limit_) {
    // The spare blocks kept for other memory types make room first.
    for (Block& block : blocks_) {
      if (block.ranges && block.ranges->empty()) {
        block_bytes_ -= block.ranges->size();
        block = Block{};
      }
    }
  }
  if (limit_ > 0 && block_bytes_ + size > limit_) {
    throw VulkanError("GPU memory: " + mib(size) + " more would pass the limit of " + mib(limit_) +
                          " (" + mib(block_bytes_) + " in use)",
                      VK_ERROR_OUT_OF_DEVICE_MEMORY);
  }
  VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
  flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
  VkMemoryAllocateInfo info{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &flags};
  info.allocationSize = size;
  info.memoryTypeIndex = type;
  VkDeviceMemory raw;
  FLUIDCAST_VK_CHECK(vkAllocateMemory(device_, &info, nullptr, &raw));
  ++allocations_made_;
  Block block;
  block.memory = UniqueMemory(device_, raw);
  block.type = type;
  // Map every host-visible block: blocks are shared by all domains that pick the same type (on
  // lavapipe and integrated GPUs one type serves all three).
  if (properties_.memoryTypes[type].propertyFlags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT) {
    FLUIDCAST_VK_CHECK(vkMapMemory(device_, raw, 0, VK_WHOLE_SIZE, 0, &block.mapped));
  }
  block.ranges = std::make_unique<RangeAllocator>(size);
  const auto offset = block.ranges->allocate(requirements.size, alignment);
  // Reuse a slot of a freed block, so that block indices held by live allocations stay valid.
  auto slot =
      std::find_if(blocks_.begin(), blocks_.end(), [](const Block& b) { return !b.ranges; });
  if (slot == blocks_.end()) slot = blocks_.insert(blocks_.end(), Block{});
  *slot = std::move(block);
  block_bytes_ += size;
  return fill(static_cast<std::size_t>(slot - blocks_.begin()), *offset);
}

void MemoryAllocator::free(std::size_t index, VkDeviceSize offset) {
  std::lock_guard lock(mutex_);
  Block& block = blocks_[index];
  block.ranges->free(offset);
  if (!block.ranges->empty()) return;
  // One empty standard block per memory type stays, so that the staging buffers of uploads and
  // snapshots do not allocate and free 64 MiB each time; the rest go back to the driver.
  const bool spare_exists = std::any_of(blocks_.begin(), blocks_.end(), [&](const Block& b) {
    return &b != &block && b.ranges && b.type == block.type && b.ranges->empty();
  });
  if (block.ranges->size() != kBlockSize || spare_exists) {
    block_bytes_ -= block.ranges->size();
    block = Block{};  // unmapped and freed
  }
}

std::uint64_t MemoryAllocator::allocations_made() const {
  std::lock_guard lock(mutex_);
  return allocations_made_;
}

std::uint64_t MemoryAllocator::block_bytes() const {
  std::lock_guard lock(mutex_);
  return block_bytes_;
}

std::size_t MemoryAllocator::block_count() const {
  std::lock_guard lock(mutex_);
  return static_cast<std::size_t>(std::count_if(
      blocks_.begin(), blocks_.end(), [](const Block& b) { return b.ranges != nullptr; }));
}

}  // namespace fluidcast::gpu

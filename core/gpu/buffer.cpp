#include "fluidcast/gpu/buffer.h"

#include <algorithm>
#include <stdexcept>

#include "fluidcast/gpu/vk_check.h"

namespace fluidcast::gpu {

Buffer::Buffer(Context& context, VkDeviceSize size, MemoryDomain domain)
    : size_(std::max<VkDeviceSize>(size, 16)) {
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = size_;
  info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT |
               VK_BUFFER_USAGE_TRANSFER_DST_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT |
               VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VkBuffer raw;
  FLUIDCAST_VK_CHECK(vkCreateBuffer(context.device(), &info, nullptr, &raw));
  buffer_ = UniqueBuffer(context.device(), raw);
  VkMemoryRequirements requirements;
  vkGetBufferMemoryRequirements(context.device(), raw, &requirements);
  memory_ = context.memory().allocate(requirements, domain);
  FLUIDCAST_VK_CHECK(vkBindBufferMemory(context.device(), raw, memory_.memory(), memory_.offset()));
  VkBufferDeviceAddressInfo address{VK_STRUCTURE_TYPE_BUFFER_DEVICE_ADDRESS_INFO};
  address.buffer = raw;
  address_ = vkGetBufferDeviceAddress(context.device(), &address);
}

void* Buffer::mapped_bytes() const {
  if (!memory_.mapped())
    throw std::logic_error("buffer: only upload and readback buffers are mapped");
  return memory_.mapped();
}

void memory_barrier(VkCommandBuffer commands, VkPipelineStageFlags from, VkAccessFlags written,
                    VkPipelineStageFlags to, VkAccessFlags accessed) {
  VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  barrier.srcAccessMask = written;
  barrier.dstAccessMask = accessed;
  vkCmdPipelineBarrier(commands, from, to, 0, 1, &barrier, 0, nullptr, 0, nullptr);
}

namespace {

constexpr VkAccessFlags kShaderAccess = VK_ACCESS_SHADER_READ_BIT | VK_ACCESS_SHADER_WRITE_BIT;
constexpr VkAccessFlags kTransferAccess =
    VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;

}  // namespace

void compute_barrier(VkCommandBuffer commands) {
  memory_barrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, VK_ACCESS_SHADER_WRITE_BIT,
                 VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, kShaderAccess);
}

void transfer_to_compute_barrier(VkCommandBuffer commands) {
  memory_barrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_ACCESS_TRANSFER_WRITE_BIT,
                 VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT, kShaderAccess);
}

void compute_to_transfer_barrier(VkCommandBuffer commands) {
  // Earlier transfers too: a copy out of a buffer that a fill then clears.
  memory_barrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                 VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT,
                 VK_PIPELINE_STAGE_TRANSFER_BIT, kTransferAccess);
}

void to_host_barrier(VkCommandBuffer commands) {
  memory_barrier(commands, VK_PIPELINE_STAGE_COMPUTE_SHADER_BIT | VK_PIPELINE_STAGE_TRANSFER_BIT,
                 VK_ACCESS_SHADER_WRITE_BIT | VK_ACCESS_TRANSFER_WRITE_BIT,
                 VK_PIPELINE_STAGE_HOST_BIT, VK_ACCESS_HOST_READ_BIT);
}

}  // namespace fluidcast::gpu

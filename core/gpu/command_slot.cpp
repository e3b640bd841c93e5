#include "fluidcast/gpu/command_slot.h"

#include <stdexcept>
#include <string>
#include <utility>

#include "fluidcast/gpu/vk_check.h"

namespace fluidcast::gpu {

CommandSlot::CommandSlot(Context& context) : context_(&context) {
  const VkDevice device = context.device();
  VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool_info.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  pool_info.queueFamilyIndex = context.queue_family();
  VkCommandPool raw_pool;
  FLUIDCAST_VK_CHECK(vkCreateCommandPool(device, &pool_info, nullptr, &raw_pool));
  pool_ = UniqueCommandPool(device, raw_pool);
  VkCommandBufferAllocateInfo allocate{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  allocate.commandPool = raw_pool;
  allocate.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  allocate.commandBufferCount = 1;
  FLUIDCAST_VK_CHECK(vkAllocateCommandBuffers(device, &allocate, &commands_));
  VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence raw_fence;
  FLUIDCAST_VK_CHECK(vkCreateFence(device, &fence_info, nullptr, &raw_fence));
  fence_ = UniqueFence(device, raw_fence);
}

VkCommandBuffer CommandSlot::begin() {
  wait();
  if (submitted_) {
    const VkFence fence = fence_.get();
    FLUIDCAST_VK_CHECK(vkResetFences(context_->device(), 1, &fence));
    submitted_ = false;
  }
  FLUIDCAST_VK_CHECK(vkResetCommandBuffer(commands_, 0));
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  FLUIDCAST_VK_CHECK(vkBeginCommandBuffer(commands_, &begin));
  return commands_;
}

CommandSlot::CommandSlot(CommandSlot&& other) noexcept
    : context_(other.context_),
      pool_(std::move(other.pool_)),
      commands_(std::exchange(other.commands_, VK_NULL_HANDLE)),
      fence_(std::move(other.fence_)),
      submitted_(std::exchange(other.submitted_, false)) {}

CommandSlot::~CommandSlot() {
  try {
    wait();
  } catch (const VulkanError&) {
    // A lost device has nothing left to wait for; the handles are destroyed all the same.
  }
}

std::uint64_t CommandSlot::submit() {
  FLUIDCAST_VK_CHECK(vkEndCommandBuffer(commands_));
  const std::uint64_t serial = context_->submit(commands_, fence_.get());
  submitted_ = true;
  return serial;
}

void CommandSlot::wait() const {
  if (!submitted_) return;
  const VkFence fence = fence_.get();
  FLUIDCAST_VK_CHECK(vkWaitForFences(context_->device(), 1, &fence, VK_TRUE, UINT64_MAX));
}

bool CommandSlot::busy() const {
  if (!submitted_) return false;
  const VkResult status = vkGetFenceStatus(context_->device(), fence_.get());
  if (status == VK_NOT_READY) return true;
  FLUIDCAST_VK_CHECK(status);
  return false;
}

TimestampQueries::TimestampQueries(Context& context, std::uint32_t capacity)
    : context_(&context), capacity_(capacity), ticks_(capacity, 0) {
  if (!context.timestamps_supported()) return;
  VkQueryPoolCreateInfo info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  info.queryType = VK_QUERY_TYPE_TIMESTAMP;
  info.queryCount = capacity;
  VkQueryPool raw;
  FLUIDCAST_VK_CHECK(vkCreateQueryPool(context.device(), &info, nullptr, &raw));
  pool_ = UniqueQueryPool(context.device(), raw);
}

void TimestampQueries::reset(VkCommandBuffer commands) {
  used_ = 0;
  fetched_ = false;
  if (pool_) vkCmdResetQueryPool(commands, pool_.get(), 0, capacity_);
}

std::uint32_t TimestampQueries::mark(VkCommandBuffer commands) {
  if (used_ == capacity_) {
    throw std::logic_error("timestamps: more than the " + std::to_string(capacity_) +
                           " marks allowed");
  }
  if (pool_) {
    vkCmdWriteTimestamp(commands, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, pool_.get(), used_);
  }
  return used_++;
}

void TimestampQueries::fetch() {
  if (!pool_ || used_ == 0 || fetched_) return;
  FLUIDCAST_VK_CHECK(vkGetQueryPoolResults(
      context_->device(), pool_.get(), 0, used_, used_ * sizeof(std::uint64_t), ticks_.data(),
      sizeof(std::uint64_t), VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT));
  fetched_ = true;
}

std::uint64_t timestamp_ticks_between(std::uint64_t from, std::uint64_t to,
                                      std::uint32_t valid_bits) {
  if (valid_bits == 0) return 0;
  const std::uint64_t range_mask =
      valid_bits >= 64 ? ~std::uint64_t{0} : (std::uint64_t{1} << valid_bits) - 1;
  const std::uint64_t ticks = (to - from) & range_mask;
  // More than half the counter's range apart: `to` came before `from` (a driver's odd reading),
  // not a wrap; no time measured.
  return ticks > range_mask / 2 ? 0 : ticks;
}

double TimestampQueries::elapsed_ms(std::uint32_t from, std::uint32_t to) {
  if (!pool_) return 0.0;
  const std::uint64_t ticks =
      timestamp_ticks_between(ticks_[from], ticks_[to], context_->timestamp_valid_bits());
  return static_cast<double>(ticks) * context_->timestamp_period_ns() * 1e-6;
}

}  // namespace fluidcast::gpu

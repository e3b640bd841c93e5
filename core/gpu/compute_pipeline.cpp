#include "fluidcast/gpu/compute_pipeline.h"

#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "fluidcast/gpu/shader_module.h"
#include "fluidcast/gpu/vk_check.h"

namespace fluidcast::gpu {

ComputePipeline::ComputePipeline(Context& context, std::span<const std::uint32_t> spirv,
                                 std::uint32_t push_constant_bytes, std::uint32_t group_size,
                                 std::span<const std::uint32_t> constants)
    : device_(context.device()),
      captured_(context.pipeline_statistics_captured()),
      push_constant_bytes_(push_constant_bytes),
      group_size_(group_size),
      max_groups_x_(context.limits().maxComputeWorkGroupCount[0]),
      max_groups_y_(context.limits().maxComputeWorkGroupCount[1]) {
  if (group_size == 0 || group_size > context.limits().maxComputeWorkGroupSize[0] ||
      group_size > context.limits().maxComputeWorkGroupInvocations) {
    throw std::invalid_argument("compute pipeline: workgroup size " + std::to_string(group_size) +
                                " is beyond the device's limit of " +
                                std::to_string(context.limits().maxComputeWorkGroupInvocations));
  }
  const VkDevice device = context.device();
  const UniqueShaderModule module = make_shader_module(device, spirv);

  VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, push_constant_bytes};
  VkPipelineLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layout_info.pushConstantRangeCount = push_constant_bytes > 0 ? 1 : 0;
  layout_info.pPushConstantRanges = &range;
  VkPipelineLayout raw_layout;
  FLUIDCAST_VK_CHECK(vkCreatePipelineLayout(device, &layout_info, nullptr, &raw_layout));
  layout_ = UniquePipelineLayout(device, raw_layout);

  std::vector<std::uint32_t> values{group_size};
  values.insert(values.end(), constants.begin(), constants.end());
  std::vector<VkSpecializationMapEntry> entries;
  for (std::uint32_t id = 0; id < values.size(); ++id) {
    entries.push_back({id, id * std::uint32_t(sizeof(std::uint32_t)), sizeof(std::uint32_t)});
  }
  const VkSpecializationInfo specialization{static_cast<std::uint32_t>(entries.size()),
                                            entries.data(), values.size() * sizeof(std::uint32_t),
                                            values.data()};
  VkComputePipelineCreateInfo info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  info.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  info.stage.module = module.get();
  info.stage.pName = "main";
  info.stage.pSpecializationInfo = &specialization;
  info.layout = raw_layout;
  if (captured_) info.flags |= VK_PIPELINE_CREATE_CAPTURE_STATISTICS_BIT_KHR;
  VkPipeline raw_pipeline;
  FLUIDCAST_VK_CHECK(
      vkCreateComputePipelines(device, VK_NULL_HANDLE, 1, &info, nullptr, &raw_pipeline));
  pipeline_ = UniquePipeline(device, raw_pipeline);
}

std::vector<PipelineStatistic> ComputePipeline::statistics() const {
  if (!captured_) return {};
  const auto get = reinterpret_cast<PFN_vkGetPipelineExecutableStatisticsKHR>(
      vkGetDeviceProcAddr(device_, "vkGetPipelineExecutableStatisticsKHR"));
  // A compute pipeline compiles to one executable.
  const VkPipelineExecutableInfoKHR executable{VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_INFO_KHR,
                                               nullptr, pipeline_.get(), 0};
  std::uint32_t count = 0;
  FLUIDCAST_VK_CHECK(get(device_, &executable, &count, nullptr));
  std::vector<VkPipelineExecutableStatisticKHR> raw(
      count, {VK_STRUCTURE_TYPE_PIPELINE_EXECUTABLE_STATISTIC_KHR});
  // VK_INCOMPLETE: fewer than the driver has, all of them valid.
  if (const VkResult result = get(device_, &executable, &count, raw.data());
      result != VK_INCOMPLETE) {
    FLUIDCAST_VK_CHECK(result);
  }
  raw.resize(count);
  std::vector<PipelineStatistic> statistics;
  for (const VkPipelineExecutableStatisticKHR& s : raw) {
    std::string value;
    switch (s.format) {
      case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_BOOL32_KHR:
        value = s.value.b32 ? "true" : "false";
        break;
      case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_INT64_KHR:
        value = std::to_string(s.value.i64);
        break;
      case VK_PIPELINE_EXECUTABLE_STATISTIC_FORMAT_UINT64_KHR:
        value = std::to_string(s.value.u64);
        break;
      default: {
        char text[32];
        std::snprintf(text, sizeof text, "%g", s.value.f64);
        value = text;
        break;
      }
    }
    statistics.push_back({s.name, value});
  }
  return statistics;
}

void ComputePipeline::check_push(std::uint32_t bytes) const {
  if (bytes != push_constant_bytes_) {
    throw std::logic_error("compute pipeline: push constants of " + std::to_string(bytes) +
                           " bytes for a layout of " + std::to_string(push_constant_bytes_));
  }
}

void ComputePipeline::bind(VkCommandBuffer commands, const void* push, std::uint32_t bytes) const {
  vkCmdBindPipeline(commands, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline_.get());
  if (bytes > 0) {
    vkCmdPushConstants(commands, layout_.get(), VK_SHADER_STAGE_COMPUTE_BIT, 0, bytes, push);
  }
}

void ComputePipeline::dispatch_bytes(VkCommandBuffer commands, const void* push,
                                     std::uint32_t bytes, std::uint64_t items) const {
  check_push(bytes);
  if (items == 0) return;
  const std::uint64_t groups = (items + group_size_ - 1) / group_size_;
  const std::uint64_t x = groups < max_groups_x_ ? groups : max_groups_x_;
  const std::uint64_t y = (groups + x - 1) / x;
  if (y > max_groups_y_) {
    throw std::invalid_argument("compute pipeline: " + std::to_string(items) +
                                " invocations exceed the device's workgroup-count limits");
  }
  bind(commands, push, bytes);
  vkCmdDispatch(commands, static_cast<std::uint32_t>(x), static_cast<std::uint32_t>(y), 1);
}

}  // namespace fluidcast::gpu

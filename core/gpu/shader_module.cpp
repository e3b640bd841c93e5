#include "fluidcast/gpu/shader_module.h"

#include "fluidcast/gpu/vk_check.h"

namespace fluidcast::gpu {

UniqueShaderModule make_shader_module(VkDevice device, std::span<const std::uint32_t> spirv) {
  VkShaderModuleCreateInfo info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  info.codeSize = spirv.size_bytes();
  info.pCode = spirv.data();
  VkShaderModule raw;
  FLUIDCAST_VK_CHECK(vkCreateShaderModule(device, &info, nullptr, &raw));
  return UniqueShaderModule(device, raw);
}

}  // namespace fluidcast::gpu

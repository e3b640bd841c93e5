// A shader module from embedded SPIR-V, for compute and graphics pipelines alike.
#pragma once

#include <cstdint>
#include <span>

#include "fluidcast/gpu/handle.h"

namespace fluidcast::gpu {

UniqueShaderModule make_shader_module(VkDevice device, std::span<const std::uint32_t> spirv);

}  // namespace fluidcast::gpu

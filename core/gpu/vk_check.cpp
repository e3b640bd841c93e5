#include "fluidcast/gpu/vk_check.h"

namespace fluidcast::gpu {

std::string_view result_name(VkResult result) {
  switch (result) {
#define FLUIDCAST_RESULT(name) \
  case name:                   \
    return #name;
    FLUIDCAST_RESULT(VK_SUCCESS)
    FLUIDCAST_RESULT(VK_NOT_READY)
    FLUIDCAST_RESULT(VK_TIMEOUT)
    FLUIDCAST_RESULT(VK_EVENT_SET)
    FLUIDCAST_RESULT(VK_EVENT_RESET)
    FLUIDCAST_RESULT(VK_INCOMPLETE)
    FLUIDCAST_RESULT(VK_ERROR_OUT_OF_HOST_MEMORY)
    FLUIDCAST_RESULT(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    FLUIDCAST_RESULT(VK_ERROR_INITIALIZATION_FAILED)
    FLUIDCAST_RESULT(VK_ERROR_DEVICE_LOST)
    FLUIDCAST_RESULT(VK_ERROR_MEMORY_MAP_FAILED)
    FLUIDCAST_RESULT(VK_ERROR_LAYER_NOT_PRESENT)
    FLUIDCAST_RESULT(VK_ERROR_EXTENSION_NOT_PRESENT)
    FLUIDCAST_RESULT(VK_ERROR_FEATURE_NOT_PRESENT)
    FLUIDCAST_RESULT(VK_ERROR_INCOMPATIBLE_DRIVER)
    FLUIDCAST_RESULT(VK_ERROR_TOO_MANY_OBJECTS)
    FLUIDCAST_RESULT(VK_ERROR_FORMAT_NOT_SUPPORTED)
    FLUIDCAST_RESULT(VK_ERROR_FRAGMENTED_POOL)
    FLUIDCAST_RESULT(VK_ERROR_UNKNOWN)
    FLUIDCAST_RESULT(VK_ERROR_OUT_OF_POOL_MEMORY)
    FLUIDCAST_RESULT(VK_ERROR_INVALID_EXTERNAL_HANDLE)
    FLUIDCAST_RESULT(VK_ERROR_FRAGMENTATION)
    FLUIDCAST_RESULT(VK_ERROR_INVALID_OPAQUE_CAPTURE_ADDRESS)
#undef FLUIDCAST_RESULT
    default:
      return "unnamed VkResult";
  }
}

void throw_vulkan_error(VkResult result, std::string_view call, std::string_view file, int line) {
  std::string what = std::string(call) + " failed with " + std::string(result_name(result)) + " (" +
                     std::to_string(static_cast<int>(result)) + ") at " + std::string(file) + ":" +
                     std::to_string(line);
  if (result == VK_ERROR_DEVICE_LOST) throw DeviceLostError(std::move(what), result);
  throw VulkanError(std::move(what), result);
}

}  // namespace fluidcast::gpu

// Always-on checking of Vulkan results: a failed call throws with the call, the VkResult's name
// and the place, in release builds too. A lost device is its own exception type, because the only
// way on from it is a new device.
#pragma once

#include <vulkan/vulkan.h>

#include <stdexcept>
#include <string>
#include <string_view>

namespace fluidcast::gpu {

std::string_view result_name(VkResult result);

class VulkanError : public std::runtime_error {
 public:
  VulkanError(std::string what, VkResult result)
      : std::runtime_error(std::move(what)), result_(result) {}
  VkResult result() const { return result_; }
  // The device or the host had no memory for the call (or the context's memory limit was met):
  // the work that asked fails, the device still serves everything else.
  bool out_of_memory() const {
    return result_ == VK_ERROR_OUT_OF_DEVICE_MEMORY || result_ == VK_ERROR_OUT_OF_HOST_MEMORY;
  }

 private:
  VkResult result_;
};

class DeviceLostError : public VulkanError {
 public:
  using VulkanError::VulkanError;
};

[[noreturn]] void throw_vulkan_error(VkResult result, std::string_view call, std::string_view file,
                                     int line);

}  // namespace fluidcast::gpu

#define FLUIDCAST_VK_CHECK(call)                                                            \
  do {                                                                                      \
    const VkResult fluidcast_vk_result = (call);                                            \
    if (fluidcast_vk_result != VK_SUCCESS) {                                                \
      ::fluidcast::gpu::throw_vulkan_error(fluidcast_vk_result, #call, __FILE__, __LINE__); \
    }                                                                                       \
  } while (false)

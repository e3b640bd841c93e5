// A headless Vulkan context: instance, the chosen physical device, a logical device with one
// compute queue, and the memory allocator. No window system is touched.
// The best device is picked unless one is asked for (ContextOptions::device_index, which
// options_from_environment() reads from FLUIDCAST_DEVICE): discrete, then integrated, virtual, CPU.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace fluidcast::gpu {

class MemoryAllocator;

// No usable Vulkan driver or device, or the one asked for does not exist: the message says what
// to install or which devices there are.
class GpuUnavailable : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct DeviceInfo {
  std::uint32_t index = 0;  // in the driver's enumeration order: what --device takes
  std::string name;
  std::string type;  // discrete, integrated, virtual, cpu, other
  std::string api_version;
  std::string driver;
  std::uint64_t device_local_bytes = 0;
  std::vector<std::string> rejected_because;  // empty when the device is usable
  std::string describe() const;               // one line
};

struct ContextOptions {
  std::optional<std::uint32_t> device_index;
  // The Khronos validation layer, when it is installed; its errors are collected (see
  // Context::validation_errors()). On by default in debug builds.
#ifdef NDEBUG
  bool validation = false;
#else
  bool validation = true;
#endif
  // Where the context says which device it chose; stderr by default.
  std::function<void(const std::string&)> log;
};

// FLUIDCAST_DEVICE=N picks device N; FLUIDCAST_VALIDATION=1 or 0 turns validation on or off.
// Throws GpuUnavailable for a value that is not a number.
ContextOptions options_from_environment(ContextOptions defaults = {});

// Every physical device with the reasons it cannot be used. Throws GpuUnavailable without a driver.
std::vector<DeviceInfo> list_devices();

class Context {
 public:
  explicit Context(ContextOptions options = options_from_environment());
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  VkDevice device() const { return device_; }
  VkPhysicalDevice physical_device() const { return physical_device_; }
  VkQueue queue() const { return queue_; }
  std::uint32_t queue_family() const { return queue_family_; }
  const VkPhysicalDeviceLimits& limits() const { return properties_.limits; }
  const DeviceInfo& info() const { return info_; }
  bool validation_enabled() const { return messenger_ != VK_NULL_HANDLE; }
  bool timestamps_supported() const { return timestamp_valid_bits_ > 0; }
  // Fragment shaders may write storage buffers (fragmentStoresAndAtomics).
  bool fragment_stores_supported() const { return fragment_stores_; }
  float timestamp_period_ns() const { return properties_.limits.timestampPeriod; }
  MemoryAllocator& memory() { return *memory_; }

  // Waits until the device has finished everything submitted: before freeing what work in flight
  // may use (rare: a buffer that must grow), never on the per-frame path.
  void wait_idle();

  // Records with `record`, submits, and waits: for uploads, read-backs and other rare work,
  // never for the per-step path.
  void run_now(const std::function<void(VkCommandBuffer)>& record);

  // Validation-layer errors and warnings since the context was made (empty without validation).
  std::vector<std::string> validation_errors() const;

 private:
  static VKAPI_ATTR VkBool32 VKAPI_CALL on_validation_message(
      VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT types,
      const VkDebugUtilsMessengerCallbackDataEXT* data, void* user);
  void release();  // what the destructor does; also when the constructor fails half-way

  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_device_ = VK_NULL_HANDLE;
  VkPhysicalDeviceProperties properties_{};
  DeviceInfo info_;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  std::uint32_t queue_family_ = 0;
  std::uint32_t timestamp_valid_bits_ = 0;
  bool fragment_stores_ = false;
  std::unique_ptr<MemoryAllocator> memory_;
  mutable std::mutex validation_mutex_;
  std::vector<std::string> validation_errors_;
};

}  // namespace fluidcast::gpu

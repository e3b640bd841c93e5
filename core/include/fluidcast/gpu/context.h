// A headless Vulkan context: instance, the chosen physical device, a logical device with one
// compute queue, and the memory allocator. No window system is touched.
// The best device is picked unless one is asked for (ContextOptions::device_index, which
// options_from_environment() reads from FLUIDCAST_DEVICE): discrete, then integrated, virtual, CPU.
#pragma once

#include <vulkan/vulkan.h>

#include <chrono>
#include <cstdint>
#include <deque>
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
  // The driver's deviceUUID (empty before Vulkan 1.2): the same device whatever the enumeration
  // order; NVIDIA's is what nvidia-smi -L prints after "GPU-".
  std::string uuid;
  std::uint64_t device_local_bytes = 0;
  // The most the device allocates in one piece (maxMemoryAllocationSize): the largest buffer.
  std::uint64_t largest_allocation_bytes = 0;
  std::vector<std::string> rejected_because;  // empty when the device is usable
  std::string describe() const;               // one line
  // A GPU of any kind, not a driver that runs Vulkan on the CPU (lavapipe, SwiftShader).
  bool hardware() const { return type != "cpu"; }
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
  // Independent blending where the device has it; off, the context runs as on a device without
  // it, so that the renderers' fallback (points) can be tried on any device.
  bool independent_blend = true;
  // The most device memory the context allocates in all, bytes (0: as much as the device gives):
  // past it an allocation fails as one the device refused (VK_ERROR_OUT_OF_DEVICE_MEMORY), so
  // that programs sharing one GPU each keep to their part. DeviceInfo::device_local_bytes of the
  // chosen device reads no more than it, so that budgets drawn from it (the GPU solver's) keep
  // within it too.
  std::uint64_t memory_limit_bytes = 0;
  // Compute pipelines keep what the driver says of their compiled code (registers and the like:
  // ComputePipeline::statistics) where the device offers VK_KHR_pipeline_executable_properties.
  // For benchmarks: a driver may compile more slowly, or skip its pipeline cache.
  bool pipeline_statistics = false;
  // Where the context says which device it chose; stderr by default.
  std::function<void(const std::string&)> log;
};

// FLUIDCAST_DEVICE=N picks device N; FLUIDCAST_VALIDATION=1 or 0 turns validation on or off;
// FLUIDCAST_INDEPENDENT_BLEND=0 leaves independent blending off.
// Throws GpuUnavailable for a value that is not a number.
ContextOptions options_from_environment(ContextOptions defaults = {});

// Every physical device with the reasons it cannot be used. Throws GpuUnavailable without a driver.
std::vector<DeviceInfo> list_devices();
// The device a Context picks when none is asked for: of the usable ones, a discrete GPU before an
// integrated one, a virtual one and a CPU, then the most device-local memory; none when no device
// is usable.
std::optional<std::uint32_t> best_device(const std::vector<DeviceInfo>& devices);

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
  std::uint32_t timestamp_valid_bits() const { return timestamp_valid_bits_; }
  // Colour attachments of one pass may blend differently (independentBlend).
  bool independent_blend_supported() const { return independent_blend_; }
  // ContextOptions::pipeline_statistics was asked for and the device offers them.
  bool pipeline_statistics_captured() const { return pipeline_statistics_; }
  float timestamp_period_ns() const { return properties_.limits.timestampPeriod; }
  MemoryAllocator& memory() { return *memory_; }

  // Every submission goes through here and gets the next serial number; the context's timeline
  // semaphore reaches that number when the submission has finished (and `fence`, if given, is
  // signalled too). Serials are how lifetime and pacing are decided: no waits on the whole device.
  std::uint64_t submit(VkCommandBuffer commands, VkFence fence = VK_NULL_HANDLE);
  std::uint64_t last_submitted() const;
  std::uint64_t last_finished() const;
  // Waits until submission `serial` has finished, at most `timeout`; returns whether it has.
  bool wait_for(std::uint64_t serial,
                std::chrono::nanoseconds timeout = std::chrono::nanoseconds::max());

  // Keeps `object` (a buffer, a renderer: anything that work in flight may use) alive until every
  // submission made so far has finished; a later submit() destroys it, on the submitting thread.
  template <class T>
  void retire(T object) {
    retire_object(std::make_unique<Retired<T>>(std::move(object)));
  }
  // Destroys the retired objects whose last submission has finished (submit() does too): for a
  // loop that may go a while without submitting.
  void release_finished();
  std::size_t retired_count() const;  // retired and not yet destroyed

  // Records with `record`, submits, and waits for that submission: for uploads, read-backs and
  // other rare work, never for the per-step path.
  void run_now(const std::function<void(VkCommandBuffer)>& record);

  // Validation-layer errors and warnings since the context was made (empty without validation).
  std::vector<std::string> validation_errors() const;

 private:
  static VKAPI_ATTR VkBool32 VKAPI_CALL on_validation_message(
      VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT types,
      const VkDebugUtilsMessengerCallbackDataEXT* data, void* user);
  void create_messenger();  // validation messages to on_validation_message
  // The device with one queue of queue_family_, and the timeline semaphore of the submissions.
  void create_device(bool independent_blend, bool pipeline_statistics);
  void release();  // what the destructor does; also when the constructor fails half-way

  struct RetiredObject {
    virtual ~RetiredObject() = default;
  };
  template <class T>
  struct Retired final : RetiredObject {
    explicit Retired(T held) : object(std::move(held)) {}
    T object;
  };
  struct RetiredAfter {
    std::uint64_t after;  // the last submission that may use it
    std::unique_ptr<RetiredObject> object;
  };
  void retire_object(std::unique_ptr<RetiredObject> object);
  // Under submit_mutex_: the retired objects whose last submission has finished.
  std::vector<std::unique_ptr<RetiredObject>> take_released(std::uint64_t finished);

  VkInstance instance_ = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_device_ = VK_NULL_HANDLE;
  VkPhysicalDeviceProperties properties_{};
  DeviceInfo info_;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  std::uint32_t queue_family_ = 0;
  std::uint32_t timestamp_valid_bits_ = 0;
  bool independent_blend_ = false;
  bool pipeline_statistics_ = false;
  std::unique_ptr<MemoryAllocator> memory_;
  VkSemaphore finished_ = VK_NULL_HANDLE;  // timeline: the serial of the newest finished submission
  mutable std::mutex submit_mutex_;        // the queue, the serial and the retired objects
  std::uint64_t last_submitted_ = 0;
  std::deque<RetiredAfter> retired_;
  mutable std::mutex validation_mutex_;
  std::vector<std::string> validation_errors_;
};

}  // namespace fluidcast::gpu

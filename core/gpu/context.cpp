#include "fluidcast/gpu/context.h"

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <limits>

#include "fluidcast/gpu/handle.h"
#include "fluidcast/gpu/memory.h"
#include "fluidcast/gpu/vk_check.h"

namespace fluidcast::gpu {
namespace {

constexpr std::uint32_t kRequiredApi = VK_API_VERSION_1_2;
constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";
constexpr const char* kInstallDriver =
    "no Vulkan driver found: install mesa-vulkan-drivers (lavapipe, which runs on the CPU) or your "
    "GPU's Vulkan driver (for NVIDIA, nvidia-driver with its Vulkan ICD)";

std::string version_string(std::uint32_t v) {
  return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) +
         "." + std::to_string(VK_API_VERSION_PATCH(v));
}

const char* type_name(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
      return "discrete";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
      return "integrated";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
      return "virtual";
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
      return "cpu";
    default:
      return "other";
  }
}

// How a device of each type ranks for the default choice: a discrete GPU before an integrated one,
// a virtual one, then a CPU.
int type_rank(const std::string& type) {
  for (int rank = 0; const char* name : {"other", "cpu", "virtual", "integrated", "discrete"}) {
    if (type == name) return rank;
    ++rank;
  }
  return 0;
}

// As the driver gives it, in the usual 8-4-4-4-12 hex groups (NVIDIA's is the UUID nvidia-smi
// shows, after "GPU-").
std::string uuid_string(const std::uint8_t (&uuid)[VK_UUID_SIZE]) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string text;
  for (std::size_t i = 0; i < VK_UUID_SIZE; ++i) {
    if (i == 4 || i == 6 || i == 8 || i == 10) text += '-';
    text += kHex[uuid[i] >> 4];
    text += kHex[uuid[i] & 15];
  }
  return text;
}

// The family the context uses: graphics and compute together when there is one (the renderer
// reads the solver's buffers in place), else compute alone.
std::optional<std::uint32_t> pick_queue_family(VkPhysicalDevice device) {
  std::uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, families.data());
  std::optional<std::uint32_t> compute_only;
  for (std::uint32_t i = 0; i < count; ++i) {
    const auto flags = families[i].queueFlags;
    if ((flags & VK_QUEUE_COMPUTE_BIT) == 0) continue;
    if (flags & VK_QUEUE_GRAPHICS_BIT) return i;
    if (!compute_only) compute_only = i;
  }
  return compute_only;
}

std::uint32_t timestamp_bits(VkPhysicalDevice device, std::uint32_t family) {
  std::uint32_t count = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, nullptr);
  std::vector<VkQueueFamilyProperties> families(count);
  vkGetPhysicalDeviceQueueFamilyProperties(device, &count, families.data());
  return families[family].timestampValidBits;
}

DeviceInfo describe_device(VkPhysicalDevice device, std::uint32_t index) {
  VkPhysicalDeviceIDProperties id{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ID_PROPERTIES};
  VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES, &id};
  VkPhysicalDeviceMaintenance3Properties maintenance{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_3_PROPERTIES, &driver};
  VkPhysicalDeviceProperties2 properties{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  vkGetPhysicalDeviceProperties(device, &properties.properties);
  const bool has_driver_properties = properties.properties.apiVersion >= VK_API_VERSION_1_2;
  if (has_driver_properties) {
    properties.pNext = &maintenance;
    vkGetPhysicalDeviceProperties2(device, &properties);
  }
  const auto& p = properties.properties;
  DeviceInfo info;
  info.index = index;
  info.name = p.deviceName;
  info.type = type_name(p.deviceType);
  info.api_version = version_string(p.apiVersion);
  info.largest_allocation_bytes = maintenance.maxMemoryAllocationSize;
  info.driver = has_driver_properties ? std::string(driver.driverName) + " " + driver.driverInfo
                                      : "driver version " + std::to_string(p.driverVersion);
  if (has_driver_properties) info.uuid = uuid_string(id.deviceUUID);

  VkPhysicalDeviceMemoryProperties memory;
  vkGetPhysicalDeviceMemoryProperties(device, &memory);
  for (std::uint32_t h = 0; h < memory.memoryHeapCount; ++h) {
    if (memory.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT) {
      info.device_local_bytes =
          std::max<std::uint64_t>(info.device_local_bytes, memory.memoryHeaps[h].size);
    }
  }

  if (p.apiVersion < kRequiredApi) {
    info.rejected_because.push_back("supports Vulkan " + info.api_version + "; 1.2 is needed");
  } else {
    VkPhysicalDeviceVulkan12Features v12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &v12};
    vkGetPhysicalDeviceFeatures2(device, &features);
    if (!v12.bufferDeviceAddress) info.rejected_because.push_back("no bufferDeviceAddress feature");
    if (!v12.timelineSemaphore) info.rejected_because.push_back("no timelineSemaphore feature");
  }
  if (!pick_queue_family(device)) info.rejected_because.push_back("no compute queue");
  return info;
}

bool lists_extension(const std::vector<VkExtensionProperties>& extensions, const char* name) {
  return std::any_of(extensions.begin(), extensions.end(), [&](const VkExtensionProperties& e) {
    return std::strcmp(e.extensionName, name) == 0;
  });
}

bool device_offers_extension(VkPhysicalDevice device, const char* name) {
  std::uint32_t count = 0;
  vkEnumerateDeviceExtensionProperties(device, nullptr, &count, nullptr);
  std::vector<VkExtensionProperties> extensions(count);
  vkEnumerateDeviceExtensionProperties(device, nullptr, &count, extensions.data());
  return lists_extension(extensions, name);
}

bool layer_installed(const char* name) {
  std::uint32_t count = 0;
  vkEnumerateInstanceLayerProperties(&count, nullptr);
  std::vector<VkLayerProperties> layers(count);
  vkEnumerateInstanceLayerProperties(&count, layers.data());
  return std::any_of(layers.begin(), layers.end(), [&](const VkLayerProperties& l) {
    return std::strcmp(l.layerName, name) == 0;
  });
}

bool layer_offers_extension(const char* layer, const char* extension) {
  std::uint32_t count = 0;
  vkEnumerateInstanceExtensionProperties(layer, &count, nullptr);
  std::vector<VkExtensionProperties> extensions(count);
  vkEnumerateInstanceExtensionProperties(layer, &count, extensions.data());
  return lists_extension(extensions, extension);
}

VkInstance create_instance(bool validation) {
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "fluidcast";
  app.apiVersion = kRequiredApi;
  std::vector<const char*> layers, extensions;
  // With validation, synchronization validation too: lavapipe runs every command in order, so a
  // missing barrier shows only on a real GPU, but the layer reports it here, for transfers and
  // images (accesses through buffer device addresses are beyond what it tracks).
  const VkValidationFeatureEnableEXT synchronization =
      VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
  VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
  features.enabledValidationFeatureCount = 1;
  features.pEnabledValidationFeatures = &synchronization;
  const bool check_synchronization =
      validation &&
      layer_offers_extension(kValidationLayer, VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
  if (validation) {
    layers.push_back(kValidationLayer);
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  }
  if (check_synchronization) extensions.push_back(VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME);
  VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  info.pNext = check_synchronization ? &features : nullptr;
  info.pApplicationInfo = &app;
  info.enabledLayerCount = static_cast<std::uint32_t>(layers.size());
  info.ppEnabledLayerNames = layers.data();
  info.enabledExtensionCount = static_cast<std::uint32_t>(extensions.size());
  info.ppEnabledExtensionNames = extensions.data();
  VkInstance instance = VK_NULL_HANDLE;
  const VkResult result = vkCreateInstance(&info, nullptr, &instance);
  if (result == VK_ERROR_INCOMPATIBLE_DRIVER) throw GpuUnavailable(kInstallDriver);
  FLUIDCAST_VK_CHECK(result);
  return instance;
}

std::vector<VkPhysicalDevice> physical_devices(VkInstance instance) {
  std::uint32_t count = 0;
  FLUIDCAST_VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, nullptr));
  std::vector<VkPhysicalDevice> devices(count);
  FLUIDCAST_VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, devices.data()));
  if (devices.empty()) throw GpuUnavailable(kInstallDriver);
  return devices;
}

// One line, so that a command-line tool can print it as its one line of error.
std::string list_for_error(const std::vector<DeviceInfo>& devices) {
  std::string text;
  for (const auto& d : devices) text += (text.empty() ? " " : "; ") + d.describe();
  return text;
}

// The device asked for, or else the best usable one (best_device). Throws GpuUnavailable naming
// the devices.
std::uint32_t choose_device(const std::vector<DeviceInfo>& infos,
                            std::optional<std::uint32_t> wanted) {
  if (wanted) {
    if (*wanted >= infos.size()) {
      throw GpuUnavailable("there is no Vulkan device " + std::to_string(*wanted) +
                           "; the devices are:" + list_for_error(infos));
    }
    if (!infos[*wanted].rejected_because.empty()) {
      throw GpuUnavailable("Vulkan device " + infos[*wanted].describe());
    }
    return *wanted;
  }
  const std::optional<std::uint32_t> best = best_device(infos);
  if (!best) throw GpuUnavailable("no usable Vulkan device:" + list_for_error(infos));
  return *best;
}

}  // namespace

std::string DeviceInfo::describe() const {
  std::string line = std::to_string(index) + ": " + name + " (" + type + ", Vulkan " + api_version +
                     ", " + driver + ", " + std::to_string(device_local_bytes >> 20) +
                     " MiB device-local" + (uuid.empty() ? "" : ", uuid " + uuid) + ")";
  for (const auto& reason : rejected_because) line += "; unusable: " + reason;
  return line;
}

ContextOptions options_from_environment(ContextOptions defaults) {
  if (const char* device = std::getenv("FLUIDCAST_DEVICE"); device && *device) {
    char* end = nullptr;
    errno = 0;
    const unsigned long index = std::strtoul(device, &end, 10);
    // 4294967296 wrapped to device 0.
    if (*end != '\0' || device[0] == '-' || errno == ERANGE ||
        index > std::numeric_limits<std::uint32_t>::max()) {
      throw GpuUnavailable(std::string("FLUIDCAST_DEVICE must be a device index, got '") + device +
                           "'");
    }
    defaults.device_index = static_cast<std::uint32_t>(index);
  }
  if (const char* validation = std::getenv("FLUIDCAST_VALIDATION"); validation && *validation) {
    defaults.validation = std::strcmp(validation, "0") != 0;
  }
  if (const char* blend = std::getenv("FLUIDCAST_INDEPENDENT_BLEND"); blend && *blend) {
    defaults.independent_blend = std::strcmp(blend, "0") != 0;
  }
  return defaults;
}

std::vector<DeviceInfo> list_devices() {
  const VkInstance instance = create_instance(false);
  std::vector<DeviceInfo> devices;
  try {
    const auto physical = physical_devices(instance);
    for (std::uint32_t i = 0; i < physical.size(); ++i) {
      devices.push_back(describe_device(physical[i], i));
    }
  } catch (...) {
    vkDestroyInstance(instance, nullptr);
    throw;
  }
  vkDestroyInstance(instance, nullptr);
  return devices;
}

std::optional<std::uint32_t> best_device(const std::vector<DeviceInfo>& devices) {
  const auto rank = [](const DeviceInfo& d) {
    return std::pair(type_rank(d.type), d.device_local_bytes);
  };
  const DeviceInfo* best = nullptr;
  for (const auto& d : devices) {
    if (d.rejected_because.empty() && (!best || rank(d) > rank(*best))) best = &d;
  }
  return best ? std::optional(best->index) : std::nullopt;
}

Context::Context(ContextOptions options) {
  const auto log =
      options.log ? options.log : [](const std::string& line) { std::cerr << line << '\n'; };
  const bool validation = options.validation && layer_installed(kValidationLayer);
  if (options.validation && !validation) {
    log("gpu: validation requested but " + std::string(kValidationLayer) +
        " is not installed (package vulkan-validationlayers); running without it");
  }
  instance_ = create_instance(validation);
  try {
    if (validation) create_messenger();
    const auto physical = physical_devices(instance_);
    std::vector<DeviceInfo> infos;
    for (std::uint32_t i = 0; i < physical.size(); ++i) {
      infos.push_back(describe_device(physical[i], i));
    }
    const std::uint32_t chosen = choose_device(infos, options.device_index);
    physical_device_ = physical[chosen];
    info_ = infos[chosen];
    if (options.memory_limit_bytes > 0)
      info_.device_local_bytes = std::min(info_.device_local_bytes, options.memory_limit_bytes);
    vkGetPhysicalDeviceProperties(physical_device_, &properties_);
    queue_family_ = *pick_queue_family(physical_device_);
    timestamp_valid_bits_ = timestamp_bits(physical_device_, queue_family_);
    create_device(options.independent_blend, options.pipeline_statistics);
    if (options.pipeline_statistics && !pipeline_statistics_) {
      log("gpu: pipeline statistics requested but the device does not offer " +
          std::string(VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME) +
          " (or its pipelineExecutableInfo feature)");
    }
    memory_ = std::make_unique<MemoryAllocator>(
        device_, physical_device_, info_.largest_allocation_bytes, options.memory_limit_bytes);
    log("gpu: using device " + info_.describe() + (validation ? ", validation on" : ""));
  } catch (...) {
    release();
    throw;
  }
}

void Context::create_messenger() {
  VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                         VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                     VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  info.pfnUserCallback = &Context::on_validation_message;
  info.pUserData = this;
  auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
      vkGetInstanceProcAddr(instance_, "vkCreateDebugUtilsMessengerEXT"));
  FLUIDCAST_VK_CHECK(create(instance_, &info, nullptr, &messenger_));
}

void Context::create_device(bool independent_blend, bool pipeline_statistics) {
  const float priority = 1.0f;
  VkDeviceQueueCreateInfo queue_info{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queue_info.queueFamilyIndex = queue_family_;
  queue_info.queueCount = 1;
  queue_info.pQueuePriorities = &priority;
  VkPhysicalDeviceVulkan12Features v12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  v12.bufferDeviceAddress = VK_TRUE;
  v12.timelineSemaphore = VK_TRUE;  // the submission serial
  // Independent blending: the fluid's pass (SSFR spheres, MC mesh) keeps the nearest distance in
  // one attachment and adds up thickness in another.
  VkPhysicalDeviceFeatures supported{};
  vkGetPhysicalDeviceFeatures(physical_device_, &supported);
  VkPhysicalDeviceFeatures features{};
  independent_blend_ = independent_blend && supported.independentBlend == VK_TRUE;
  features.independentBlend = independent_blend_ ? VK_TRUE : VK_FALSE;
  VkPhysicalDevicePipelineExecutablePropertiesFeaturesKHR executable_info{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PIPELINE_EXECUTABLE_PROPERTIES_FEATURES_KHR};
  std::vector<const char*> extensions;
  if (pipeline_statistics &&
      device_offers_extension(physical_device_,
                              VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME)) {
    VkPhysicalDeviceFeatures2 offered{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2,
                                      &executable_info};
    vkGetPhysicalDeviceFeatures2(physical_device_, &offered);
    pipeline_statistics_ = executable_info.pipelineExecutableInfo == VK_TRUE;
  }
  if (pipeline_statistics_) {
    extensions.push_back(VK_KHR_PIPELINE_EXECUTABLE_PROPERTIES_EXTENSION_NAME);
    v12.pNext = &executable_info;
  }
  VkDeviceCreateInfo device_info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO, &v12};
  device_info.queueCreateInfoCount = 1;
  device_info.pQueueCreateInfos = &queue_info;
  device_info.pEnabledFeatures = &features;
  device_info.enabledExtensionCount = static_cast<std::uint32_t>(extensions.size());
  device_info.ppEnabledExtensionNames = extensions.data();
  FLUIDCAST_VK_CHECK(vkCreateDevice(physical_device_, &device_info, nullptr, &device_));
  vkGetDeviceQueue(device_, queue_family_, 0, &queue_);
  VkSemaphoreTypeCreateInfo timeline_type{VK_STRUCTURE_TYPE_SEMAPHORE_TYPE_CREATE_INFO};
  timeline_type.semaphoreType = VK_SEMAPHORE_TYPE_TIMELINE;
  timeline_type.initialValue = 0;
  VkSemaphoreCreateInfo timeline_info{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO, &timeline_type};
  FLUIDCAST_VK_CHECK(vkCreateSemaphore(device_, &timeline_info, nullptr, &finished_));
}

Context::~Context() { release(); }

void Context::release() {
  if (device_) {
    // The end of the context, not of a frame: whatever is still retired goes now.
    vkDeviceWaitIdle(device_);
    while (!retired_.empty()) {  // a retired object's destructor may retire another
      auto released = std::exchange(retired_, {});
      released.clear();
    }
  }
  memory_.reset();
  if (finished_) vkDestroySemaphore(device_, std::exchange(finished_, VK_NULL_HANDLE), nullptr);
  if (device_) vkDestroyDevice(std::exchange(device_, VK_NULL_HANDLE), nullptr);
  if (messenger_) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    destroy(instance_, std::exchange(messenger_, VK_NULL_HANDLE), nullptr);
  }
  if (instance_) vkDestroyInstance(std::exchange(instance_, VK_NULL_HANDLE), nullptr);
}

std::uint64_t Context::submit(VkCommandBuffer commands, VkFence fence) {
  std::vector<std::unique_ptr<RetiredObject>> finished;
  std::uint64_t serial;
  {
    std::lock_guard lock(submit_mutex_);
    serial = last_submitted_ + 1;
    VkTimelineSemaphoreSubmitInfo timeline{VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO};
    timeline.signalSemaphoreValueCount = 1;
    timeline.pSignalSemaphoreValues = &serial;
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO, &timeline};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &commands;
    submit.signalSemaphoreCount = 1;
    submit.pSignalSemaphores = &finished_;
    FLUIDCAST_VK_CHECK(vkQueueSubmit(queue_, 1, &submit, fence));
    last_submitted_ = serial;
    finished = take_released(last_finished());
  }
  return serial;  // `finished` is destroyed here, outside the lock
}

std::uint64_t Context::last_submitted() const {
  std::lock_guard lock(submit_mutex_);
  return last_submitted_;
}

std::uint64_t Context::last_finished() const {
  std::uint64_t value = 0;
  FLUIDCAST_VK_CHECK(vkGetSemaphoreCounterValue(device_, finished_, &value));
  return value;
}

bool Context::wait_for(std::uint64_t serial, std::chrono::nanoseconds timeout) {
  VkSemaphoreWaitInfo wait{VK_STRUCTURE_TYPE_SEMAPHORE_WAIT_INFO};
  wait.semaphoreCount = 1;
  wait.pSemaphores = &finished_;
  wait.pValues = &serial;
  const auto nanoseconds = static_cast<std::uint64_t>(std::max<std::int64_t>(0, timeout.count()));
  const VkResult result = vkWaitSemaphores(device_, &wait, nanoseconds);
  if (result == VK_TIMEOUT) return false;
  FLUIDCAST_VK_CHECK(result);
  return true;
}

void Context::retire_object(std::unique_ptr<RetiredObject> object) {
  std::lock_guard lock(submit_mutex_);
  retired_.push_back({last_submitted_, std::move(object)});
}

std::vector<std::unique_ptr<Context::RetiredObject>> Context::take_released(
    std::uint64_t finished) {
  std::vector<std::unique_ptr<RetiredObject>> released;
  // Retired in submission order, so the finished ones are at the front.
  while (!retired_.empty() && retired_.front().after <= finished) {
    released.push_back(std::move(retired_.front().object));
    retired_.pop_front();
  }
  return released;
}

void Context::release_finished() {
  std::vector<std::unique_ptr<RetiredObject>> finished;
  {
    std::lock_guard lock(submit_mutex_);
    finished = take_released(last_finished());
  }
}  // `finished` is destroyed here, outside the lock

std::size_t Context::retired_count() const {
  std::lock_guard lock(submit_mutex_);
  return retired_.size();
}

void Context::run_now(const std::function<void(VkCommandBuffer)>& record) {
  VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool_info.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
  pool_info.queueFamilyIndex = queue_family_;
  VkCommandPool raw_pool;
  FLUIDCAST_VK_CHECK(vkCreateCommandPool(device_, &pool_info, nullptr, &raw_pool));
  const UniqueCommandPool pool(device_, raw_pool);

  VkCommandBufferAllocateInfo allocate{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  allocate.commandPool = pool.get();
  allocate.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  allocate.commandBufferCount = 1;
  VkCommandBuffer command_buffer;
  FLUIDCAST_VK_CHECK(vkAllocateCommandBuffers(device_, &allocate, &command_buffer));
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  FLUIDCAST_VK_CHECK(vkBeginCommandBuffer(command_buffer, &begin));
  record(command_buffer);
  FLUIDCAST_VK_CHECK(vkEndCommandBuffer(command_buffer));
  // On the timeline, not a fence: lavapipe signalled a fence of the same submission before the
  // timeline's value showed it (last_finished() read 0 after the wait), and callers read both.
  wait_for(submit(command_buffer), std::chrono::nanoseconds::max());
}

std::vector<std::string> Context::validation_errors() const {
  std::lock_guard lock(validation_mutex_);
  return validation_errors_;
}

VkBool32 Context::on_validation_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                        VkDebugUtilsMessageTypeFlagsEXT,
                                        const VkDebugUtilsMessengerCallbackDataEXT* data,
                                        void* user) {
  auto* context = static_cast<Context*>(user);
  const std::string message =
      std::string(severity >= VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? "error: "
                                                                            : "warning: ") +
      (data->pMessage ? data->pMessage : "");
  std::cerr << "vulkan validation " << message << '\n';
  std::lock_guard lock(context->validation_mutex_);
  context->validation_errors_.push_back(message);
  return VK_FALSE;
}

}  // namespace fluidcast::gpu

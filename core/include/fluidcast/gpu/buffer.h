// A storage buffer with its memory. Every buffer can be read and written by shaders through its
// device address, copied to and from, and hold indirect draws; in the upload and readback domains
// it is mapped.
#pragma once

#include <cstddef>
#include <span>

#include "fluidcast/gpu/context.h"
#include "fluidcast/gpu/memory.h"

namespace fluidcast::gpu {

class Buffer {
 public:
  Buffer() = default;
  // A size of 0 is rounded up to a small buffer: Vulkan has no empty ones.
  Buffer(Context& context, VkDeviceSize size, MemoryDomain domain);

  VkBuffer get() const { return buffer_.get(); }
  VkDeviceSize size() const { return size_; }
  VkDeviceAddress address() const { return address_; }
  explicit operator bool() const { return static_cast<bool>(buffer_); }

  // The mapped contents (upload and readback domains only; throws std::logic_error otherwise).
  template <class T>
  std::span<T> mapped() const {
    return {static_cast<T*>(mapped_bytes()), static_cast<std::size_t>(size_ / sizeof(T))};
  }

 private:
  void* mapped_bytes() const;

  Allocation memory_;
  UniqueBuffer buffer_;  // declared after its memory, so destroyed before it
  VkDeviceSize size_ = 0;
  VkDeviceAddress address_ = 0;
};

// One global memory barrier: what `from` stages wrote (`written`) is visible to the `to` stages'
// `accessed` kinds of access; with no accesses, an execution dependency (write after read).
void memory_barrier(VkCommandBuffer commands, VkPipelineStageFlags from, VkAccessFlags written,
                    VkPipelineStageFlags to, VkAccessFlags accessed);
// Ordering between recorded commands. Compute writes before compute reads and writes is the
// common case: one global barrier between dependent dispatches.
void compute_barrier(VkCommandBuffer commands);
// Transfers (fill, update, copy) before compute, and compute before transfers.
void transfer_to_compute_barrier(VkCommandBuffer commands);
void compute_to_transfer_barrier(VkCommandBuffer commands);
// Device writes made visible to the host after the submission's fence.
void to_host_barrier(VkCommandBuffer commands);

}  // namespace fluidcast::gpu

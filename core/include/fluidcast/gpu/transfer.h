// Copies between host memory and device buffers through a staging buffer, waiting for the copy.
// For setup, snapshots and tests: the per-step path never waits like this.
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "fluidcast/gpu/buffer.h"

namespace fluidcast::gpu {

// Bytes for a device buffer at an offset, or from one.
struct Upload {
  const Buffer& destination;
  std::span<const std::byte> bytes;
  VkDeviceSize offset = 0;
};
struct Download {
  const Buffer& source;
  std::span<std::byte> bytes;
  VkDeviceSize offset = 0;
};

// All of them through one staging buffer in one submission, and one wait: each wait also waits
// for everything queued before it. Throws std::out_of_range for a range beyond its buffer,
// before anything is copied.
void upload_all(Context& context, std::span<const Upload> uploads);
void download_all(Context& context, std::span<const Download> downloads);

void upload_bytes(Context& context, const Buffer& destination, std::span<const std::byte> bytes,
                  VkDeviceSize offset = 0);
void download_bytes(Context& context, const Buffer& source, std::span<std::byte> bytes,
                    VkDeviceSize offset = 0);

template <class T>
void upload(Context& context, const Buffer& destination, std::span<const T> values) {
  upload_bytes(context, destination, std::as_bytes(values));
}

template <class T>
std::vector<T> download(Context& context, const Buffer& source, std::size_t count) {
  std::vector<T> values(count);
  download_bytes(context, source, std::as_writable_bytes(std::span<T>(values)));
  return values;
}

}  // namespace fluidcast::gpu

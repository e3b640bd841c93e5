#include "fluidcast/gpu/transfer.h"

#include <cstring>
#include <stdexcept>
#include <string>

namespace fluidcast::gpu {
namespace {

void check_range(const Buffer& buffer, std::size_t bytes, VkDeviceSize offset) {
  if (offset + bytes > buffer.size()) {
    throw std::out_of_range("transfer of " + std::to_string(bytes) + " bytes at offset " +
                            std::to_string(offset) + " beyond a buffer of " +
                            std::to_string(buffer.size()));
  }
}

}  // namespace

void upload_bytes(Context& context, const Buffer& destination, std::span<const std::byte> bytes,
                  VkDeviceSize offset) {
  if (bytes.empty()) return;
  check_range(destination, bytes.size(), offset);
  const Buffer staging(context, bytes.size(), MemoryDomain::upload);
  std::memcpy(staging.mapped<std::byte>().data(), bytes.data(), bytes.size());
  context.run_now([&](VkCommandBuffer commands) {
    compute_to_transfer_barrier(commands);
    const VkBufferCopy region{0, offset, bytes.size()};
    vkCmdCopyBuffer(commands, staging.get(), destination.get(), 1, &region);
    transfer_to_compute_barrier(commands);
  });
}

void download_bytes(Context& context, const Buffer& source, std::span<std::byte> bytes,
                    VkDeviceSize offset) {
  if (bytes.empty()) return;
  check_range(source, bytes.size(), offset);
  const Buffer staging(context, bytes.size(), MemoryDomain::readback);
  context.run_now([&](VkCommandBuffer commands) {
    compute_to_transfer_barrier(commands);
    const VkBufferCopy region{offset, 0, bytes.size()};
    vkCmdCopyBuffer(commands, source.get(), staging.get(), 1, &region);
    to_host_barrier(commands);
  });
  std::memcpy(bytes.data(), staging.mapped<std::byte>().data(), bytes.size());
}

}  // namespace fluidcast::gpu

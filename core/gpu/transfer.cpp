#include "fluidcast/gpu/transfer.h"

#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace fluidcast::gpu {
namespace {

void check_range(const Buffer& buffer, std::size_t bytes, VkDeviceSize offset) {
  if (offset + bytes > buffer.size()) {
    throw std::out_of_range("transfer of " + std::to_string(bytes) + " bytes at offset " +
                            std::to_string(offset) + " beyond a buffer of " +
                            std::to_string(buffer.size()));
  }
}

// The bytes of all `transfers`, once each is known to fit the buffer `device_side` names.
template <class Transfer, class DeviceSide>
std::size_t checked_total(std::span<const Transfer> transfers, DeviceSide device_side) {
  std::size_t total = 0;
  for (const Transfer& transfer : transfers) {
    check_range(device_side(transfer), transfer.bytes.size(), transfer.offset);
    total += transfer.bytes.size();
  }
  return total;
}

}  // namespace

void upload_all(Context& context, std::span<const Upload> uploads) {
  const std::size_t total = checked_total(
      uploads, [](const Upload& upload) -> const Buffer& { return upload.destination; });
  if (total == 0) return;
  const Buffer staging(context, total, MemoryDomain::upload);
  std::byte* const staged = staging.mapped<std::byte>().data();
  std::vector<VkBufferCopy> regions;
  VkDeviceSize at = 0;
  for (const Upload& upload : uploads) {
    // An empty span's data() may be null, which memcpy may not be given even for no bytes.
    if (!upload.bytes.empty()) std::memcpy(staged + at, upload.bytes.data(), upload.bytes.size());
    regions.push_back({at, upload.offset, upload.bytes.size()});
    at += upload.bytes.size();
  }
  context.run_now([&](VkCommandBuffer commands) {
    compute_to_transfer_barrier(commands);
    for (std::size_t k = 0; k < uploads.size(); ++k) {
      if (regions[k].size > 0) {
        vkCmdCopyBuffer(commands, staging.get(), uploads[k].destination.get(), 1, &regions[k]);
      }
    }
    transfer_to_compute_barrier(commands);
  });
}

void download_all(Context& context, std::span<const Download> downloads) {
  const std::size_t total = checked_total(
      downloads, [](const Download& download) -> const Buffer& { return download.source; });
  if (total == 0) return;
  const Buffer staging(context, total, MemoryDomain::readback);
  std::vector<VkBufferCopy> regions;
  VkDeviceSize at = 0;
  for (const Download& download : downloads) {
    regions.push_back({download.offset, at, download.bytes.size()});
    at += download.bytes.size();
  }
  context.run_now([&](VkCommandBuffer commands) {
    compute_to_transfer_barrier(commands);
    for (std::size_t k = 0; k < downloads.size(); ++k) {
      if (regions[k].size > 0) {
        vkCmdCopyBuffer(commands, downloads[k].source.get(), staging.get(), 1, &regions[k]);
      }
    }
    to_host_barrier(commands);
  });
  const std::byte* const staged = staging.mapped<std::byte>().data();
  for (std::size_t k = 0; k < downloads.size(); ++k) {
    if (downloads[k].bytes.empty()) continue;  // its data() may be null, as memcpy's may not
    std::memcpy(downloads[k].bytes.data(), staged + regions[k].dstOffset,
                downloads[k].bytes.size());
  }
}

void upload_bytes(Context& context, const Buffer& destination, std::span<const std::byte> bytes,
                  VkDeviceSize offset) {
  const Upload upload{destination, bytes, offset};
  upload_all(context, {&upload, 1});
}

void download_bytes(Context& context, const Buffer& source, std::span<std::byte> bytes,
                    VkDeviceSize offset) {
  const Download download{source, bytes, offset};
  download_all(context, {&download, 1});
}

}  // namespace fluidcast::gpu

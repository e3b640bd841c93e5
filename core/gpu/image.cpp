#include "fluidcast/gpu/image.h"

#include <stdexcept>
#include <string>

#include "fluidcast/gpu/vk_check.h"

namespace fluidcast::gpu {

Image::Image(Context& context, std::uint32_t width, std::uint32_t height, VkFormat format,
             VkImageUsageFlags usage, VkImageAspectFlags aspect)
    : format_(format), width_(width), height_(height) {
  const std::uint32_t limit = context.limits().maxImageDimension2D;
  if (width == 0 || height == 0 || width > limit || height > limit) {
    throw std::invalid_argument("image: size " + std::to_string(width) + "×" +
                                std::to_string(height) + " must be 1 to " + std::to_string(limit) +
                                " (the device's maxImageDimension2D) on each side");
  }
  const VkDevice device = context.device();
  VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  info.imageType = VK_IMAGE_TYPE_2D;
  info.format = format;
  info.extent = {width, height, 1};
  info.mipLevels = 1;
  info.arrayLayers = 1;
  info.samples = VK_SAMPLE_COUNT_1_BIT;
  info.tiling = VK_IMAGE_TILING_OPTIMAL;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  VkImage raw;
  FLUIDCAST_VK_CHECK(vkCreateImage(device, &info, nullptr, &raw));
  image_ = UniqueImage(device, raw);
  VkMemoryRequirements requirements;
  vkGetImageMemoryRequirements(device, raw, &requirements);
  memory_ = context.memory().allocate(requirements, MemoryDomain::device, Resource::optimal_image);
  FLUIDCAST_VK_CHECK(vkBindImageMemory(device, raw, memory_.memory(), memory_.offset()));

  VkImageViewCreateInfo view_info{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  view_info.image = raw;
  view_info.viewType = VK_IMAGE_VIEW_TYPE_2D;
  view_info.format = format;
  view_info.subresourceRange = {aspect, 0, 1, 0, 1};
  VkImageView raw_view;
  FLUIDCAST_VK_CHECK(vkCreateImageView(device, &view_info, nullptr, &raw_view));
  view_ = UniqueImageView(device, raw_view);
}

}  // namespace fluidcast::gpu

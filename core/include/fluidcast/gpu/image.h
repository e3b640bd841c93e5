// A 2D image in device memory with one view of all of it: render targets and the textures the
// renderer's passes read.
#pragma once

#include "fluidcast/gpu/context.h"
#include "fluidcast/gpu/handle.h"
#include "fluidcast/gpu/memory.h"

namespace fluidcast::gpu {

class Image {
 public:
  Image() = default;
  // Throws std::invalid_argument for a size beyond the device's maxImageDimension2D, naming it.
  Image(Context& context, std::uint32_t width, std::uint32_t height, VkFormat format,
        VkImageUsageFlags usage, VkImageAspectFlags aspect);

  VkImage get() const { return image_.get(); }
  VkImageView view() const { return view_.get(); }
  VkFormat format() const { return format_; }
  std::uint32_t width() const { return width_; }
  std::uint32_t height() const { return height_; }

 private:
  Allocation memory_;
  UniqueImage image_;     // after its memory, so destroyed before it
  UniqueImageView view_;  // destroyed before its image
  VkFormat format_ = VK_FORMAT_UNDEFINED;
  std::uint32_t width_ = 0, height_ = 0;
};

}  // namespace fluidcast::gpu

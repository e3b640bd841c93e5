#include "fluid_target.h"

#include <limits>
#include <utility>

#include "render_pass.h"

namespace fluidcast::render {
namespace {

gpu::UniqueRenderPass make_pass(VkDevice device) {
  // Distance, thickness and spray: cleared, left ready to be copied out.
  const VkAttachmentDescription attachments[3] = {
      cleared_attachment(FluidTarget::kFloatFormat, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL),
      cleared_attachment(FluidTarget::kFloatFormat, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL),
      cleared_attachment(FluidTarget::kFloatFormat, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL)};
  const VkAttachmentReference colour_refs[3] = {{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL},
                                                {1, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL},
                                                {2, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL}};
  VkSubpassDescription subpass{};
  subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  subpass.colorAttachmentCount = 3;
  subpass.pColorAttachments = colour_refs;
  // Before: the previous frame's copies out of the attachments. After: this frame's.
  VkSubpassDependency before{};
  before.srcSubpass = VK_SUBPASS_EXTERNAL;
  before.dstSubpass = 0;
  before.srcStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
  before.srcAccessMask = 0;
  before.dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  before.dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  VkSubpassDependency after{};
  after.srcSubpass = 0;
  after.dstSubpass = VK_SUBPASS_EXTERNAL;
  after.srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  after.srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  after.dstStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
  after.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  const VkSubpassDependency dependencies[2] = {before, after};
  return make_render_pass(device, attachments, subpass, dependencies);
}

}  // namespace

bool FluidTarget::supported(const gpu::Context& context) {
  VkFormatProperties properties;
  vkGetPhysicalDeviceFormatProperties(context.physical_device(), kFloatFormat, &properties);
  return context.independent_blend_supported() &&
         (properties.optimalTilingFeatures & VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT) != 0;
}

FluidTarget::FluidTarget(gpu::Context& context, const RenderTarget& scene)
    : width_(scene.width()),
      height_(scene.height()),
      distance_(context, width_, height_, kFloatFormat,
                VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                VK_IMAGE_ASPECT_COLOR_BIT),
      thickness_(context, width_, height_, kFloatFormat,
                 VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                 VK_IMAGE_ASPECT_COLOR_BIT),
      spray_(context, width_, height_, kFloatFormat,
             VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
             VK_IMAGE_ASPECT_COLOR_BIT),
      pass_(make_pass(context.device())) {
  const VkImageView views[3] = {distance_.view(), thickness_.view(), spray_.view()};
  framebuffer_ = make_framebuffer(context.device(), pass_.get(), views, width_, height_);
}

void FluidTarget::begin(VkCommandBuffer commands) const {
  VkClearValue values[3];
  values[0].color = {{std::numeric_limits<float>::infinity(), 0.0f, 0.0f, 0.0f}};
  values[1].color = {{0.0f, 0.0f, 0.0f, 0.0f}};
  values[2].color = {{0.0f, 0.0f, 0.0f, 0.0f}};
  begin_render_pass(commands, pass_.get(), framebuffer_.get(), width_, height_, values);
}

void FluidTarget::end(VkCommandBuffer commands) const { vkCmdEndRenderPass(commands); }

void FluidTarget::record_read(VkCommandBuffer commands, const gpu::Buffer& distance,
                              const gpu::Buffer& thickness, const gpu::Buffer& spray) const {
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {width_, height_, 1};
  const std::pair<const gpu::Image*, const gpu::Buffer*> copies[3] = {
      {&distance_, &distance}, {&thickness_, &thickness}, {&spray_, &spray}};
  for (const auto& [image, buffer] : copies) {
    vkCmdCopyImageToBuffer(commands, image->get(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                           buffer->get(), 1, &region);
  }
}

}  // namespace fluidcast::render

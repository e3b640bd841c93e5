#include "fluidcast/render/render_target.h"

#include <stdexcept>
#include <string>

#include "render_pass.h"

namespace fluidcast::render {
namespace {

void check_size(const gpu::Context& context, std::uint32_t width, std::uint32_t height) {
  const auto& limits = context.limits();
  const std::uint32_t max_width = std::min(limits.maxFramebufferWidth, limits.maxImageDimension2D);
  const std::uint32_t max_height =
      std::min(limits.maxFramebufferHeight, limits.maxImageDimension2D);
  if (width == 0 || height == 0 || width > max_width || height > max_height) {
    throw std::invalid_argument("frame size " + std::to_string(width) + "×" +
                                std::to_string(height) + " is outside 1×1 to " +
                                std::to_string(max_width) + "×" + std::to_string(max_height) +
                                " (this device's framebuffer limits)");
  }
}

// Clears the colour and stores it, to be copied out.
gpu::UniqueRenderPass make_scene_pass(VkDevice device) {
  const VkAttachmentDescription attachments[1] = {
      cleared_attachment(RenderTarget::kColourFormat, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL)};
  const VkAttachmentReference colour_ref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
  VkSubpassDescription subpass{};
  subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  subpass.colorAttachmentCount = 1;
  subpass.pColorAttachments = &colour_ref;
  // The previous frame's copy out of the colour image comes before this frame's clear.
  VkSubpassDependency dependency{};
  dependency.srcSubpass = VK_SUBPASS_EXTERNAL;
  dependency.dstSubpass = 0;
  dependency.srcStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
  dependency.srcAccessMask = 0;
  dependency.dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  dependency.dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  // And the colour written here comes before the copy to the host.
  VkSubpassDependency to_copy{};
  to_copy.srcSubpass = 0;
  to_copy.dstSubpass = VK_SUBPASS_EXTERNAL;
  to_copy.srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT;
  to_copy.srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT;
  to_copy.dstStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT;
  to_copy.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
  const VkSubpassDependency dependencies[2] = {dependency, to_copy};
  return make_render_pass(device, attachments, subpass, dependencies);
}

}  // namespace

RenderTarget::RenderTarget(gpu::Context& context, std::uint32_t width, std::uint32_t height)
    : colour_((check_size(context, width, height),
               gpu::Image(context, width, height, kColourFormat,
                          VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                          VK_IMAGE_ASPECT_COLOR_BIT))) {
  pass_ = make_scene_pass(context.device());

  const VkImageView views[1] = {colour_.view()};
  framebuffer_ = make_framebuffer(context.device(), pass_.get(), views, width, height);
}

void RenderTarget::begin(VkCommandBuffer commands, const float background[4]) const {
  VkClearValue clear[1];
  clear[0].color = {{background[0], background[1], background[2], background[3]}};
  begin_render_pass(commands, pass_.get(), framebuffer_.get(), width(), height(), clear);
}

void RenderTarget::end(VkCommandBuffer commands) const { vkCmdEndRenderPass(commands); }

}  // namespace fluidcast::render

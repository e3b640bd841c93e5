#include "render_pass.h"

#include "fluidcast/gpu/vk_check.h"

namespace fluidcast::render {

VkAttachmentDescription cleared_attachment(VkFormat format, VkImageLayout final_layout) {
  VkAttachmentDescription attachment{};
  attachment.format = format;
  attachment.samples = VK_SAMPLE_COUNT_1_BIT;
  attachment.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  attachment.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  attachment.stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  attachment.stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  attachment.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  attachment.finalLayout = final_layout;
  return attachment;
}

gpu::UniqueRenderPass make_render_pass(VkDevice device,
                                       std::span<const VkAttachmentDescription> attachments,
                                       const VkSubpassDescription& subpass,
                                       std::span<const VkSubpassDependency> dependencies) {
  VkRenderPassCreateInfo info{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
  info.attachmentCount = static_cast<std::uint32_t>(attachments.size());
  info.pAttachments = attachments.data();
  info.subpassCount = 1;
  info.pSubpasses = &subpass;
  info.dependencyCount = static_cast<std::uint32_t>(dependencies.size());
  info.pDependencies = dependencies.data();
  VkRenderPass raw;
  FLUIDCAST_VK_CHECK(vkCreateRenderPass(device, &info, nullptr, &raw));
  return gpu::UniqueRenderPass(device, raw);
}

gpu::UniqueFramebuffer make_framebuffer(VkDevice device, VkRenderPass pass,
                                        std::span<const VkImageView> views, std::uint32_t width,
                                        std::uint32_t height) {
  VkFramebufferCreateInfo info{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
  info.renderPass = pass;
  info.attachmentCount = static_cast<std::uint32_t>(views.size());
  info.pAttachments = views.data();
  info.width = width;
  info.height = height;
  info.layers = 1;
  VkFramebuffer raw;
  FLUIDCAST_VK_CHECK(vkCreateFramebuffer(device, &info, nullptr, &raw));
  return gpu::UniqueFramebuffer(device, raw);
}

void begin_render_pass(VkCommandBuffer commands, VkRenderPass pass, VkFramebuffer framebuffer,
                       std::uint32_t width, std::uint32_t height,
                       std::span<const VkClearValue> clear) {
  VkRenderPassBeginInfo info{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  info.renderPass = pass;
  info.framebuffer = framebuffer;
  info.renderArea = {{0, 0}, {width, height}};
  info.clearValueCount = static_cast<std::uint32_t>(clear.size());
  info.pClearValues = clear.data();
  vkCmdBeginRenderPass(commands, &info, VK_SUBPASS_CONTENTS_INLINE);
  const VkViewport viewport{0.0f, 0.0f, float(width), float(height), 0.0f, 1.0f};
  const VkRect2D scissor{{0, 0}, {width, height}};
  vkCmdSetViewport(commands, 0, 1, &viewport);
  vkCmdSetScissor(commands, 0, 1, &scissor);
}

}  // namespace fluidcast::render

// What every render pass of the renderer does the same way (RenderTarget, FluidTarget): create the
// pass and its framebuffer, and begin it over the whole target with the viewport and scissor set.
#pragma once

#include <cstdint>
#include <span>

#include "fluidcast/gpu/handle.h"

namespace fluidcast::render {

// An attachment cleared at the start of its pass (what it held before is dropped) and stored,
// ending in `final_layout`.
VkAttachmentDescription cleared_attachment(VkFormat format, VkImageLayout final_layout);

gpu::UniqueRenderPass make_render_pass(VkDevice device,
                                       std::span<const VkAttachmentDescription> attachments,
                                       const VkSubpassDescription& subpass,
                                       std::span<const VkSubpassDependency> dependencies);
gpu::UniqueFramebuffer make_framebuffer(VkDevice device, VkRenderPass pass,
                                        std::span<const VkImageView> views, std::uint32_t width,
                                        std::uint32_t height);
void begin_render_pass(VkCommandBuffer commands, VkRenderPass pass, VkFramebuffer framebuffer,
                       std::uint32_t width, std::uint32_t height,
                       std::span<const VkClearValue> clear);

}  // namespace fluidcast::render

#include "fluid_target.h"

#include <limits>

#include "fluidcast/gpu/vk_check.h"
#include "fluidcast/render/render_target.h"

namespace fluidcast::render {
namespace {

constexpr VkPipelineStageFlags kFragmentTests =
    VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
constexpr VkAccessFlags kDepthAccess =
    VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;

// A float colour attachment, cleared and left ready to be copied out, and the fluid's depth,
// loaded from `depth_from` (the layout the step before left it in).
gpu::UniqueRenderPass make_pass(VkDevice device, VkImageLayout depth_from,
                                VkAttachmentStoreOp depth_store) {
  VkAttachmentDescription attachments[2] = {};
  attachments[0].format = FluidTarget::kFloatFormat;
  attachments[0].samples = VK_SAMPLE_COUNT_1_BIT;
  attachments[0].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
  attachments[0].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
  attachments[0].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
  attachments[0].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
  attachments[0].initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  attachments[0].finalLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
  attachments[1] = attachments[0];
  attachments[1].format = RenderTarget::kDepthFormat;
  attachments[1].loadOp = VK_ATTACHMENT_LOAD_OP_LOAD;
  attachments[1].storeOp = depth_store;
  attachments[1].initialLayout = depth_from;
  attachments[1].finalLayout = VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
  const VkAttachmentReference colour_ref{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
  const VkAttachmentReference depth_ref{1, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
  VkSubpassDescription subpass{};
  subpass.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  subpass.colorAttachmentCount = 1;
  subpass.pColorAttachments = &colour_ref;
  subpass.pDepthStencilAttachment = &depth_ref;
  // Before: the copy of the scene's depth in, the previous frame's copies out of the colour, and
  // the pass before's depth tests. After: the copies out, and the next pass's depth tests.
  VkSubpassDependency before{};
  before.srcSubpass = VK_SUBPASS_EXTERNAL;
  before.dstSubpass = 0;
  before.srcStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT | kFragmentTests;
  before.srcAccessMask =
      VK_ACCESS_TRANSFER_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
  before.dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | kFragmentTests;
  before.dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | kDepthAccess;
  VkSubpassDependency after{};
  after.srcSubpass = 0;
  after.dstSubpass = VK_SUBPASS_EXTERNAL;
  after.srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | kFragmentTests;
  after.srcAccessMask =
      VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
  after.dstStageMask = VK_PIPELINE_STAGE_TRANSFER_BIT | kFragmentTests;
  after.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT | kDepthAccess;
  const VkSubpassDependency dependencies[2] = {before, after};
  VkRenderPassCreateInfo info{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
  info.attachmentCount = 2;
  info.pAttachments = attachments;
  info.subpassCount = 1;
  info.pSubpasses = &subpass;
  info.dependencyCount = 2;
  info.pDependencies = dependencies;
  VkRenderPass raw;
  FLUIDCAST_VK_CHECK(vkCreateRenderPass(device, &info, nullptr, &raw));
  return gpu::UniqueRenderPass(device, raw);
}

gpu::UniqueFramebuffer make_framebuffer(VkDevice device, VkRenderPass pass, VkImageView colour,
                                        VkImageView depth, std::uint32_t width,
                                        std::uint32_t height) {
  const VkImageView views[2] = {colour, depth};
  VkFramebufferCreateInfo info{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
  info.renderPass = pass;
  info.attachmentCount = 2;
  info.pAttachments = views;
  info.width = width;
  info.height = height;
  info.layers = 1;
  VkFramebuffer raw;
  FLUIDCAST_VK_CHECK(vkCreateFramebuffer(device, &info, nullptr, &raw));
  return gpu::UniqueFramebuffer(device, raw);
}

VkImageMemoryBarrier depth_barrier(VkImage image, VkImageLayout from, VkImageLayout to,
                                   VkAccessFlags written, VkAccessFlags accessed) {
  VkImageMemoryBarrier barrier{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
  barrier.srcAccessMask = written;
  barrier.dstAccessMask = accessed;
  barrier.oldLayout = from;
  barrier.newLayout = to;
  barrier.srcQueueFamilyIndex = barrier.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
  barrier.image = image;
  barrier.subresourceRange = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 1, 0, 1};
  return barrier;
}

}  // namespace

bool FluidTarget::supported(const gpu::Context& context) {
  VkFormatProperties properties;
  vkGetPhysicalDeviceFormatProperties(context.physical_device(), kFloatFormat, &properties);
  return (properties.optimalTilingFeatures & VK_FORMAT_FEATURE_COLOR_ATTACHMENT_BLEND_BIT) != 0;
}

FluidTarget::FluidTarget(gpu::Context& context, std::uint32_t width, std::uint32_t height)
    : width_(width),
      height_(height),
      distance_(context, width, height, kFloatFormat,
                VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                VK_IMAGE_ASPECT_COLOR_BIT),
      thickness_(context, width, height, kFloatFormat,
                 VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT,
                 VK_IMAGE_ASPECT_COLOR_BIT),
      depth_(context, width, height, RenderTarget::kDepthFormat,
             VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT,
             VK_IMAGE_ASPECT_DEPTH_BIT) {
  const VkDevice device = context.device();
  // The thickness pass takes the depth as the copy left it and keeps it for the surface pass,
  // which writes the fluid's own into it and need not keep it.
  thickness_pass_ =
      make_pass(device, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_ATTACHMENT_STORE_OP_STORE);
  surface_pass_ = make_pass(device, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
                            VK_ATTACHMENT_STORE_OP_DONT_CARE);
  thickness_framebuffer_ = make_framebuffer(device, thickness_pass_.get(), thickness_.view(),
                                            depth_.view(), width, height);
  surface_framebuffer_ =
      make_framebuffer(device, surface_pass_.get(), distance_.view(), depth_.view(), width, height);
}

void FluidTarget::record_start(VkCommandBuffer commands, const gpu::Image& scene_depth) const {
  const VkImageMemoryBarrier to_copy[2] = {
      depth_barrier(scene_depth.get(), VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
                    VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                    VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, VK_ACCESS_TRANSFER_READ_BIT),
      // The previous frame's fluid depth is not needed: its layout may be dropped.
      depth_barrier(depth_.get(), VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                    0, VK_ACCESS_TRANSFER_WRITE_BIT)};
  vkCmdPipelineBarrier(commands, kFragmentTests, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0,
                       nullptr, 2, to_copy);
  VkImageCopy region{};
  region.srcSubresource = {VK_IMAGE_ASPECT_DEPTH_BIT, 0, 0, 1};
  region.dstSubresource = region.srcSubresource;
  region.extent = {width_, height_, 1};
  vkCmdCopyImage(commands, scene_depth.get(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, depth_.get(),
                 VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
  // The scene's depth goes back to where a later frame of the same camera starts from.
  const VkImageMemoryBarrier back =
      depth_barrier(scene_depth.get(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                    VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL, 0, kDepthAccess);
  vkCmdPipelineBarrier(commands, VK_PIPELINE_STAGE_TRANSFER_BIT, kFragmentTests, 0, 0, nullptr, 0,
                       nullptr, 1, &back);
}

void FluidTarget::begin(VkCommandBuffer commands, VkRenderPass pass, VkFramebuffer framebuffer,
                        float clear) const {
  VkClearValue values[2];
  values[0].color = {{clear, 0.0f, 0.0f, 0.0f}};
  values[1].depthStencil = {1.0f, 0};
  VkRenderPassBeginInfo info{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  info.renderPass = pass;
  info.framebuffer = framebuffer;
  info.renderArea = {{0, 0}, {width_, height_}};
  info.clearValueCount = 2;
  info.pClearValues = values;
  vkCmdBeginRenderPass(commands, &info, VK_SUBPASS_CONTENTS_INLINE);
  const VkViewport viewport{0.0f, 0.0f, float(width_), float(height_), 0.0f, 1.0f};
  const VkRect2D scissor{{0, 0}, {width_, height_}};
  vkCmdSetViewport(commands, 0, 1, &viewport);
  vkCmdSetScissor(commands, 0, 1, &scissor);
}

void FluidTarget::begin_thickness(VkCommandBuffer commands) const {
  begin(commands, thickness_pass_.get(), thickness_framebuffer_.get(), 0.0f);
}

void FluidTarget::begin_surface(VkCommandBuffer commands) const {
  begin(commands, surface_pass_.get(), surface_framebuffer_.get(),
        std::numeric_limits<float>::infinity());
}

void FluidTarget::end(VkCommandBuffer commands) const { vkCmdEndRenderPass(commands); }

void FluidTarget::record_read(VkCommandBuffer commands, const gpu::Buffer& distance,
                              const gpu::Buffer& thickness) const {
  VkBufferImageCopy region{};
  region.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
  region.imageExtent = {width_, height_, 1};
  vkCmdCopyImageToBuffer(commands, distance_.get(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                         distance.get(), 1, &region);
  vkCmdCopyImageToBuffer(commands, thickness_.get(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                         thickness.get(), 1, &region);
}

}  // namespace fluidcast::render

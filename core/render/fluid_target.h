// Where SSFR draws its spheres through the rasterizer: the nearest sphere's view distance by the
// hardware depth test, and the water crossed by additive blending, each a float per pixel in an
// attachment of its own, then copied into the buffers the screen-space passes read. The fluid's
// depth starts as a copy of the scene's (RenderTarget's), which stays as it was for the next
// frame of the same camera.
#pragma once

#include "fluidcast/gpu/buffer.h"
#include "fluidcast/gpu/image.h"

namespace fluidcast::render {

class FluidTarget {
 public:
  static constexpr VkFormat kFloatFormat = VK_FORMAT_R32_SFLOAT;

  // Whether the device can blend the float attachments (COLOR_ATTACHMENT_BLEND of R32_SFLOAT).
  static bool supported(const gpu::Context& context);
  FluidTarget(gpu::Context& context, std::uint32_t width, std::uint32_t height);

  VkRenderPass thickness_pass() const { return thickness_pass_.get(); }
  VkRenderPass surface_pass() const { return surface_pass_.get(); }

  // The scene's depth (after RenderTarget's pass) into the fluid's depth.
  void record_start(VkCommandBuffer commands, const gpu::Image& scene_depth) const;
  // Thickness first (tested against the scene's depth alone), then the surface (which writes
  // depth); each between begin and end.
  void begin_thickness(VkCommandBuffer commands) const;
  void begin_surface(VkCommandBuffer commands) const;
  void end(VkCommandBuffer commands) const;
  // Distances (+inf where no sphere is) and thicknesses into buffers of a float per pixel.
  void record_read(VkCommandBuffer commands, const gpu::Buffer& distance,
                   const gpu::Buffer& thickness) const;

 private:
  void begin(VkCommandBuffer commands, VkRenderPass pass, VkFramebuffer framebuffer,
             float clear) const;

  std::uint32_t width_, height_;
  gpu::Image distance_, thickness_, depth_;
  gpu::UniqueRenderPass thickness_pass_, surface_pass_;
  gpu::UniqueFramebuffer thickness_framebuffer_, surface_framebuffer_;
};

}  // namespace fluidcast::render

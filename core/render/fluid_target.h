// Where Marching Cubes draws its mesh, in one pass: the nearest surface's view distance, the water
// crossed and the spray crossed (none: the mesh is all surface), each a float per pixel in an
// attachment of its own, combined by the blend units (minimum, sum, sum). Then all three are
// copied into the buffers the screen-space passes read, as SSFR's particle pass fills them.
#pragma once

#include "fluidcast/gpu/buffer.h"
#include "fluidcast/gpu/image.h"
#include "fluidcast/render/render_target.h"

namespace fluidcast::render {

class FluidTarget {
 public:
  static constexpr VkFormat kFloatFormat = VK_FORMAT_R32_SFLOAT;

  // Whether the device can blend the float attachments (COLOR_ATTACHMENT_BLEND of R32_SFLOAT),
  // each its own way (independentBlend).
  static bool supported(const gpu::Context& context);
  // Of `scene`'s size.
  FluidTarget(gpu::Context& context, const RenderTarget& scene);

  VkRenderPass render_pass() const { return pass_.get(); }

  // Clears distance to +inf, thickness and spray to 0 and begins the pass.
  void begin(VkCommandBuffer commands) const;
  void end(VkCommandBuffer commands) const;
  // Distances (+inf where no surface is), thicknesses (m) and spray (particle diameters) into
  // buffers of a float per pixel.
  void record_read(VkCommandBuffer commands, const gpu::Buffer& distance,
                   const gpu::Buffer& thickness, const gpu::Buffer& spray) const;

 private:
  std::uint32_t width_, height_;
  gpu::Image distance_, thickness_, spray_;
  gpu::UniqueRenderPass pass_;
  gpu::UniqueFramebuffer framebuffer_;
};

}  // namespace fluidcast::render

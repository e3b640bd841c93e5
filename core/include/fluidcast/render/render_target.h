// Where the scene around the fluid is drawn, with no window: a colour image (RGBA8, copied out
// after its pass), with the render pass and framebuffer that clear and fill it.
#pragma once

#include "fluidcast/gpu/image.h"

namespace fluidcast::render {

class RenderTarget {
 public:
  static constexpr VkFormat kColourFormat = VK_FORMAT_R8G8B8A8_UNORM;

  // Throws std::invalid_argument for a size of zero or beyond the device's limits, naming them.
  RenderTarget(gpu::Context& context, std::uint32_t width, std::uint32_t height);

  std::uint32_t width() const { return colour_.width(); }
  std::uint32_t height() const { return colour_.height(); }
  VkRenderPass render_pass() const { return pass_.get(); }
  const gpu::Image& colour() const { return colour_; }

  // Begins the render pass, clearing the colour to `background`; viewport and scissor cover the
  // target. The pass ends with the colour image ready to be copied from.
  void begin(VkCommandBuffer commands, const float background[4]) const;
  void end(VkCommandBuffer commands) const;

 private:
  gpu::Image colour_;
  gpu::UniqueRenderPass pass_;
  gpu::UniqueFramebuffer framebuffer_;
};

}  // namespace fluidcast::render

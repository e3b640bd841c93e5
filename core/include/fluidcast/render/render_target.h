// Where a frame is drawn, with no window: a colour image (RGBA8, copied to the host after the
// frame) and a depth image, with the render pass and framebuffer that clear and fill them.
#pragma once

#include "fluidcast/gpu/image.h"

namespace fluidcast::render {

class RenderTarget {
 public:
  static constexpr VkFormat kColourFormat = VK_FORMAT_R8G8B8A8_UNORM;
  static constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
  // clear: colour and depth cleared. keep_depth: the depth the previous pass left (a scene drawn
  // earlier for the same camera), the colour undefined.
  enum class Start { clear, keep_depth };

  // Throws std::invalid_argument for a size of zero or beyond the device's limits, naming them.
  RenderTarget(gpu::Context& context, std::uint32_t width, std::uint32_t height);

  std::uint32_t width() const { return colour_.width(); }
  std::uint32_t height() const { return colour_.height(); }
  // Pipelines made for it work in both passes (they differ only in load operations).
  VkRenderPass render_pass() const { return clearing_pass_.get(); }
  const gpu::Image& colour() const { return colour_; }
  // The scene's depth, which SSFR's sphere pass tests against (FluidTarget).
  const gpu::Image& depth() const { return depth_; }

  // Begins the render pass, clearing to `background` (or keeping the depth); viewport and scissor
  // cover the target. The pass ends with the colour image ready to be copied from.
  void begin(VkCommandBuffer commands, const float background[4], Start start) const;
  void end(VkCommandBuffer commands) const;

 private:
  gpu::Image colour_, depth_;
  gpu::UniqueRenderPass clearing_pass_, keeping_pass_;
  gpu::UniqueFramebuffer framebuffer_;
};

}  // namespace fluidcast::render

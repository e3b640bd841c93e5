// One graphics pipeline of the renderer: a vertex and a fragment shader drawing into a pass of
// the RenderTarget or the FluidTarget, with no vertex buffers (shaders read what they need by
// device address) and the DrawConstants as push constants.
#pragma once

#include <span>
#include <vector>

#include "fluidcast/gpu/context.h"
#include "fluidcast/gpu/handle.h"
#include "frame_params.h"

namespace fluidcast::render {

// How a colour attachment combines what a fragment writes with what it holds.
enum class Blend { replace, add, min };

struct PipelineOptions {
  std::vector<Blend> attachments = {Blend::replace};  // one per colour attachment of the pass
};

class GraphicsPipeline {
 public:
  GraphicsPipeline(gpu::Context& context, VkRenderPass render_pass,
                   std::span<const std::uint32_t> vertex, std::span<const std::uint32_t> fragment,
                   PipelineOptions options);
  // Inside the render pass.
  void draw(VkCommandBuffer commands, const DrawConstants& constants, std::uint32_t vertices) const;
  // The vertex count comes from a VkDrawIndirectCommand the GPU wrote into `indirect`.
  void draw_indirect(VkCommandBuffer commands, const DrawConstants& constants,
                     VkBuffer indirect) const;

 private:
  gpu::UniquePipelineLayout layout_;
  gpu::UniquePipeline pipeline_;
};

}  // namespace fluidcast::render
